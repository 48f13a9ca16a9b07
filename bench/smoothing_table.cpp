// Chooses the default smoothing by measurement (docs/STUDY.md): for each input and candidate
// setting, the volume change against the unsmoothed mesh, how far the surface moved (symmetric
// deviation), how much staircase is left (mean angle between the normals of adjacent triangles;
// a voxel staircase has many right angles) and the mean radii ratio. Marching Cubes, every part.
//   segmesh_smoothing_table LABELMAP...
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh_io/read_volume.hpp"

using namespace segmesh;

namespace {

// Mean angle (degrees) between the normals of triangles sharing an edge.
double roughness(const TriMesh& m) {
  std::vector<std::vector<std::pair<uint32_t, size_t>>> by_vertex(m.positions.size());
  std::vector<Vec3d> normal(m.triangle_count());
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const Vec3d a = to_double(m.positions[m.indices[3 * t]]);
    const Vec3d n = cross(to_double(m.positions[m.indices[3 * t + 1]]) - a,
                          to_double(m.positions[m.indices[3 * t + 2]]) - a);
    const double l = norm(n);
    normal[t] = l > 0 ? (1 / l) * n : n;
    for (int k = 0; k < 3; ++k) {
      const uint32_t u = m.indices[3 * t + k], v = m.indices[3 * t + (k + 1) % 3];
      by_vertex[std::min(u, v)].push_back({std::max(u, v), t});
    }
  }
  double sum = 0;
  size_t n = 0;
  for (auto& list : by_vertex) {
    std::sort(list.begin(), list.end());
    for (size_t i = 0; i + 1 < list.size(); ++i) {
      if (list[i].first != list[i + 1].first) continue;
      const double c = std::clamp(dot(normal[list[i].second], normal[list[i + 1].second]), -1.0, 1.0);
      sum += std::acos(c) * 180 / std::numbers::pi;
      ++n;
    }
  }
  return n ? sum / double(n) : 0;
}

TriMesh merged(const Scene& scene) {
  TriMesh all;
  for (const Part& p : scene.parts) {
    const uint32_t base = static_cast<uint32_t>(all.positions.size());
    all.positions.insert(all.positions.end(), p.mesh.positions.begin(), p.mesh.positions.end());
    for (uint32_t i : p.mesh.indices) all.indices.push_back(base + i);
  }
  return all;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<SmoothOptions> settings;
  auto add = [&](SmoothMethod m, int iterations, double pass_band = 0.01) {
    SmoothOptions o;
    o.method = m;
    o.iterations = iterations;
    o.pass_band = pass_band;
    o.sinc_unit_gain = false;   // the plain filters, windowed sinc as VTK / 3D Slicer
    o.preserve_volume = false;
    settings.push_back(o);
  };
  add(SmoothMethod::none, 0);
  add(SmoothMethod::laplacian, 2);
  for (int n : {2, 5}) add(SmoothMethod::hc, n);
  for (int n : {10, 20, 40, 100}) add(SmoothMethod::taubin, n);
  for (double pb : {0.1, 0.01, 0.001}) add(SmoothMethod::sinc, 20, pb);
  add(SmoothMethod::sinc, 40, 0.01);
  settings.push_back(resolve_meshing_options({}).smooth);  // last row: segmesh's default
  std::printf("| input | smoothing | volume change | deviation mean / p95 (mm) | normal angle (deg) | rho mean |\n");
  std::printf("| --- | --- | ---: | --- | ---: | ---: |\n");
  for (int a = 1; a < argc; ++a) {
    const Image image = read_volume(argv[a]);
    MeshingOptions o;
    o.smooth = {};
    const Scene base = build_scene(image, o);
    const TriMesh before = merged(base);
    double v0 = 0;
    for (const Part& p : base.parts) v0 += measure_mesh(p.mesh).volume_mm3;
    const std::string name = std::string(argv[a]).substr(std::string(argv[a]).find_last_of('/') + 1);
    for (const SmoothOptions& s : settings) {
      Scene scene = base;
      smooth_scene(scene, s);
      double v = 0;
      for (const Part& p : scene.parts) v += measure_mesh(p.mesh).volume_mm3;
      const TriMesh after = merged(scene);
      const Deviation d = s.method == SmoothMethod::none ? Deviation{0, 0, 0} : mesh_deviation(before, after);
      char label[96];
      std::snprintf(label, sizeof label, "%s%s x%d%s", s.preserve_volume ? "segmesh default: " : "",
                    std::string(smooth_method_name(s.method)).c_str(),
                    s.iterations, s.method == SmoothMethod::sinc ? (" pb " + std::to_string(s.pass_band).substr(0, 5)).c_str() : "");
      std::printf("| %s | %s | %+.3f %% | %.4f / %.4f | %.2f | %.3f |\n", name.c_str(), label,
                  100 * (v - v0) / v0, d.mean, d.p95, roughness(after), triangle_quality(after).mean);
      std::fflush(stdout);
    }
  }
}
