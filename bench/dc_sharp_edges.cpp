// Sharp edges, accuracy and triangle quality of Dual Contouring against Marching Cubes on analytic
// fields and the phantom: the measurements behind Dual Contouring's defaults
// (docs/DUAL_CONTOURING.md, "Sharp edges by default").
//   segmesh_dc_sharp_edges [--no-phantom]
// - cube: a cube of half-side 6 mm as a sampled signed distance field, voxel 0.6 mm, in six
//   rotations (the first, 0.5 rad about each axis, is issue 39's); per rotation the 90th
//   percentile of the distance from points on its true edges to the raw mesh (no smoothing),
//   Dual Contouring over Marching Cubes; the mean and the worst of the six ratios; the volume
//   error and mean radii ratio of the first;
// - sphere: radius 10 mm on the same grid, area and volume against 4 pi r^2 and 4/3 pi r^3;
// - phantom: make_phantom() through the pipeline's extraction (label parts), mean radii ratio;
// - ms: Dual Contouring of the six cubes and the sphere, best of 3, all threads.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "segmesh/dual_contouring.hpp"
#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "support/sharp_shapes.hpp"
#include "support/test_fields.hpp"

using namespace segmesh;

namespace {

constexpr double kVoxel = 0.6, kHalfSide = 6, kRadius = 10;

struct Cube {
  test::RotatedCube shape;
  Volume<float> field;
  std::vector<Vec3d> edges;
  double mc_p90 = 0;
};

std::vector<Cube> cubes() {
  const double angles[6][3] = {{0.5, 0.5, 0.5}, {0.3, 0.5, 0.2}, {0.6, 0.4, 0.5},
                               {0.1, 0.2, 0.3}, {1.0, 0.5, 0.25}, {0.4, -0.3, 0.7}};
  std::vector<Cube> out;
  for (const auto& a : angles) {
    Cube c{{test::rotation(a[0], a[1], a[2]), kHalfSide}, {}, {}};
    c.field = test::sample(test::centred_grid(kHalfSide * 1.8 + 2, kVoxel), c.shape);
    c.edges = c.shape.edge_points();
    c.mc_p90 = test::p90_distance(marching_cubes(c.field, {.iso = 0}), c.edges);
    out.push_back(std::move(c));
  }
  return out;
}

double rel(double a, double exact) { return 100 * (a - exact) / exact; }

double phantom_rho(const Image& phantom, const PipelineParts& parts, const MeshingOptions& o) {
  const Scene scene = extract_parts(phantom, parts, o);
  double sum = 0, n = 0;
  for (const Part& p : scene.parts) {
    const QualityStats q = triangle_quality(p.mesh);
    sum += q.mean * double(q.triangles);
    n += double(q.triangles);
  }
  return sum / n;
}

struct Variant {
  std::string name;
  DcOptions options;
};

}  // namespace

int main(int argc, char** argv) {
  const bool with_phantom = !(argc > 1 && std::strcmp(argv[1], "--no-phantom") == 0);
  const std::vector<Cube> cube = cubes();
  const Volume<float> sphere_field = test::sample(test::centred_grid(kRadius + 2, kVoxel),
                                                  [](Vec3d p) { return kRadius - norm(p); });
  const double pi = std::numbers::pi;
  const double sphere_area = 4 * pi * kRadius * kRadius,
               sphere_volume = 4.0 / 3 * pi * kRadius * kRadius * kRadius;
  Image phantom;
  PipelineParts parts;
  if (with_phantom) {
    phantom.path = "phantom";
    phantom.voxel_type = "uint8";
    phantom.volume = make_phantom();
    parts = find_parts(phantom, {.method = Method::dual_contouring});
  }
  std::printf("| method | first cube p90 mm | / MC | mean / MC | worst / MC | cube volume | cube rho "
              "| degenerate | sphere area | sphere volume | phantom rho | ms |\n");
  std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  {
    const TriMesh mc = marching_cubes(cube[0].field, {.iso = 0});
    const MeshMeasures s = measure_mesh(marching_cubes(sphere_field, {.iso = 0}));
    std::printf("| mc | %.3f | 1 | 1 | 1 | %+.3f %% | %.3f | | %+.3f %% | %+.3f %% | %s | |\n",
                cube[0].mc_p90, rel(measure_mesh(mc).volume_mm3, cube[0].shape.volume()),
                triangle_quality(mc).mean, rel(s.area_mm2, sphere_area),
                rel(s.volume_mm3, sphere_volume),
                with_phantom ? std::to_string(phantom_rho(phantom, parts, {})).c_str() : "");
  }
  std::vector<Variant> variants{{"dc, defaults", {.iso = 0}}};
  // Before issue 39: linear Hermite data, vertices 5 % inside their cells.
  for (double eps : {0.5, 0.3, 0.2, 0.1}) {
    variants.push_back({"dc, linear, in cell, svd eps " + std::to_string(eps).substr(0, 4),
                        {.iso = 0, .svd_eps = eps, .hermite = DcHermite::linear,
                         .cell_reach = -kDcCellMargin}});
  }
  for (DcHermite hermite : {DcHermite::linear, DcHermite::cubic}) {
    for (double reach : {-kDcCellMargin, 0.0, 0.1, 0.25, 0.5}) {
      for (double eps : {0.5, 0.2}) {
        char name[96];
        std::snprintf(name, sizeof name, "dc, %s, reach %+.2f, svd eps %.2f",
                      hermite == DcHermite::cubic ? "cubic" : "linear", reach, eps);
        variants.push_back({name, {.iso = 0, .svd_eps = eps, .hermite = hermite, .cell_reach = reach}});
      }
    }
  }
  for (const Variant& v : variants) {
    std::vector<TriMesh> meshes(cube.size());
    TriMesh sphere;
    double ms = 1e300;
    for (int repeat = 0; repeat < 3; ++repeat) {
      const auto start = std::chrono::steady_clock::now();
      for (size_t c = 0; c < cube.size(); ++c) meshes[c] = dual_contouring(cube[c].field, v.options);
      sphere = dual_contouring(sphere_field, v.options);
      ms = std::min(ms, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
    double sum = 0, worst = 0, first = 0;
    int64_t degenerate = measure_mesh(sphere).degenerate_triangles;
    for (size_t c = 0; c < cube.size(); ++c) {
      degenerate += measure_mesh(meshes[c]).degenerate_triangles;
      const double p90 = test::p90_distance(meshes[c], cube[c].edges);
      if (c == 0) first = p90;
      sum += p90 / cube[c].mc_p90;
      worst = std::max(worst, p90 / cube[c].mc_p90);
    }
    const MeshMeasures s = measure_mesh(sphere);
    std::string rho;
    if (with_phantom) {
      MeshingOptions o{.method = Method::dual_contouring, .dc_svd_eps = v.options.svd_eps};
      rho = std::to_string(phantom_rho(phantom, parts, o));
    }
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f | %+.3f %% | %.3f | %lld | %+.3f %% | %+.3f %% | %s | %.1f |\n",
                v.name.c_str(), first, first / cube[0].mc_p90, sum / double(cube.size()), worst,
                rel(measure_mesh(meshes[0]).volume_mm3, cube[0].shape.volume()),
                triangle_quality(meshes[0]).mean, (long long)degenerate, rel(s.area_mm2, sphere_area),
                rel(s.volume_mm3, sphere_volume), rho.c_str(), ms);
  }
}
