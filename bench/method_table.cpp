// Prints Markdown tables comparing Marching Cubes and Dual Contouring on label maps: vertices,
// triangles, extraction time (best of 3, all threads), radii ratio and volume against the voxel
// volume; and what Gaussian pre-smoothing does to volumes. The meshes are the raw extraction
// (pipeline.hpp's extract_parts: no smoothing), timed as the pipeline runs it.
//   segmesh_method_table FILE...
#include <chrono>
#include <cstdio>
#include <string>

#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh_io/read_volume.hpp"

using namespace segmesh;

namespace {

struct Row {
  int64_t vertices = 0, triangles = 0;
  double ms = 1e300, rho_mean = 0, rho_min = 1, volume = 0, voxel_volume = 0;
  bool closed = true;
};

Row run(const Image& image, const MeshingOptions& o) {
  Row row;
  const PipelineParts parts = find_parts(image, o);
  for (int repeat = 0; repeat < 3; ++repeat) {
    const auto start = std::chrono::steady_clock::now();
    const Scene scene = extract_parts(image, parts, o);
    row.ms = std::min(row.ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (repeat > 0) continue;
    double rho_sum = 0;
    for (const Part& p : scene.parts) {
      const MeshMeasures m = measure_mesh(p.mesh);
      const QualityStats q = triangle_quality(p.mesh);
      row.vertices += m.vertices;
      row.triangles += m.triangles;
      rho_sum += q.mean * double(q.triangles);
      row.rho_min = std::min(row.rho_min, q.min);
      row.volume += m.volume_mm3;
      row.voxel_volume += p.voxel_volume_mm3;
      row.closed = row.closed && m.closed();
    }
    row.rho_mean = rho_sum / double(row.triangles);
  }
  return row;
}

std::string base(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

}  // namespace

int main(int argc, char** argv) {
  std::printf("| input | method | vertices | triangles | extract ms | rho mean | rho min | volume vs voxels | closed |\n");
  std::printf("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n");
  for (int a = 1; a < argc; ++a) {
    const Image image = read_volume(argv[a]);
    const auto& s = image.grid().spacing;
    const double tolerance = 0.25 * std::min({s[0], s[1], s[2]});
    for (double tol : {0.0, -1.0, tolerance}) {
      const Method method = tol == 0 ? Method::marching_cubes : Method::dual_contouring;
      const Row r = run(image, {.method = method, .dc_tolerance_mm = std::max(tol, 0.0)});
      char name[64];
      std::snprintf(name, sizeof name, "%s", std::string(method_name(method)).c_str());
      if (tol > 0) std::snprintf(name, sizeof name, "dc, tolerance %.2f mm", tol);
      std::printf("| %s | %s | %lld | %lld | %.0f | %.3f | %.4f | %+.2f %% | %s |\n", base(argv[a]).c_str(),
                  name, (long long)r.vertices,
                  (long long)r.triangles, r.ms, r.rho_mean, r.rho_min,
                  100 * (r.volume - r.voxel_volume) / r.voxel_volume, r.closed ? "yes" : "NO");
    }
  }
  std::printf("\n| input | method | presmooth sigma | triangles | rho mean | volume vs voxels | closed |\n");
  std::printf("| --- | --- | ---: | ---: | ---: | ---: | --- |\n");
  for (int a = 1; a < argc; ++a) {
    const Image image = read_volume(argv[a]);
    const auto& s = image.grid().spacing;
    const double voxel = std::min({s[0], s[1], s[2]});
    for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
      for (double f : {0.5, 1.0, 2.0}) {
        const Row r = run(image, {.method = method, .volume_sigma_mm = f * voxel});
        std::printf("| %s | %s | %.2f mm (%.1f voxel) | %lld | %.3f | %+.2f %% | %s |\n",
                    base(argv[a]).c_str(), std::string(method_name(method)).c_str(), f * voxel, f,
                    (long long)r.triangles, r.rho_mean,
                    100 * (r.volume - r.voxel_volume) / r.voxel_volume, r.closed ? "yes" : "NO");
      }
    }
  }
}
