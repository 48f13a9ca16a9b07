// The deviation between a mesh and its moved copy (same triangles) against independent
// references: a brute-force loop over every sample and triangle on small meshes, and
// mesh_deviation's general path (two MeshDistance trees, no shared triangles) on the phantom.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "segmesh/marching_cubes.hpp"
#include "segmesh/moved_mesh_deviation.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh/smoothing.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

TriMesh sphere(double r, double spacing) {
  Volume<float> field;
  const auto n = static_cast<int64_t>(2 * (r + 2) / spacing) + 1;
  field.grid.dims = {n, n, n};
  field.grid.spacing = {spacing, spacing, spacing};
  const double half = spacing * double(n - 1) / 2;
  field.grid.origin = {-half, -half, -half};
  field.voxels.resize(field.grid.voxel_count());
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i)
        field.at(i, j, k) =
            static_cast<float>(r - norm(field.grid.to_world({double(i), double(j), double(k)})));
  return marching_cubes(field, {.iso = 0});
}

// Every sample's distance by a loop over every triangle: the definition, nothing shared with the
// code under test but closest_point_on_triangle (tested on its own in test_mesh_distance.cpp).
Deviation brute_force(const TriMesh& a, const TriMesh& b) {
  std::vector<double> d;
  auto to_mesh = [](const TriMesh& from, const TriMesh& to, std::vector<double>& out) {
    std::vector<Vec3d> samples;
    std::vector<char> used(from.positions.size(), 0);
    for (uint32_t v : from.indices) used[v] = 1;
    for (size_t v = 0; v < used.size(); ++v)
      if (used[v]) samples.push_back(to_double(from.positions[v]));
    for (size_t t = 0; t < from.triangle_count(); ++t) {
      Vec3d c{};
      for (int k = 0; k < 3; ++k) c = c + to_double(from.positions[from.indices[3 * t + k]]);
      samples.push_back((1.0 / 3.0) * c);
    }
    for (const Vec3d& p : samples) {
      double best = INFINITY;
      for (size_t t = 0; t < to.triangle_count(); ++t) {
        const Vec3d q = closest_point_on_triangle(p, to_double(to.positions[to.indices[3 * t]]),
                                                  to_double(to.positions[to.indices[3 * t + 1]]),
                                                  to_double(to.positions[to.indices[3 * t + 2]]));
        best = std::min(best, norm(p - q));
      }
      out.push_back(best);
    }
  };
  to_mesh(a, b, d);
  to_mesh(b, a, d);
  Deviation dev;
  double sum = 0;
  for (double x : d) sum += x;
  dev.mean = sum / double(d.size());
  dev.hausdorff = *std::max_element(d.begin(), d.end());
  dev.p95 = percentile(d, 0.95);
  return dev;
}

// The same surface with every triangle's corners rotated (a, b, c) -> (b, c, a): different index
// arrays, so mesh_deviation takes its general path.
TriMesh rotated_corners(TriMesh m) {
  for (size_t t = 0; t < m.triangle_count(); ++t)
    std::rotate(m.indices.begin() + 3 * t, m.indices.begin() + 3 * t + 1, m.indices.begin() + 3 * t + 3);
  return m;
}

TEST(MovedMeshDeviation, EqualsBruteForceOnRandomlyMovedSmallMeshes) {
  std::mt19937 rng(7);
  for (double amplitude : {0.0, 0.01, 0.2, 1.5}) {
    const TriMesh a = sphere(3, 0.9);
    ASSERT_GT(a.triangle_count(), 200u);
    TriMesh b = a;
    std::uniform_real_distribution<double> u(-amplitude, amplitude);
    for (Vec3f& p : b.positions) p = to_float(to_double(p) + Vec3d{u(rng), u(rng), u(rng)});
    const Deviation fast = moved_mesh_deviation(a.positions, b);
    const Deviation slow = brute_force(a, b);
    EXPECT_NEAR(fast.hausdorff, slow.hausdorff, 1e-12) << amplitude;
    EXPECT_NEAR(fast.mean, slow.mean, 1e-12) << amplitude;
    EXPECT_NEAR(fast.p95, slow.p95, 1e-12) << amplitude;
    if (amplitude == 0) {
      EXPECT_EQ(fast.hausdorff, 0.0);
    }
  }
}

TEST(MovedMeshDeviation, IsSymmetricAndMatchesTheGeneralPath) {
  const TriMesh a = sphere(10, 0.5);
  TriMesh b = a;
  smooth_mesh(b, {.method = SmoothMethod::laplacian, .iterations = 10});
  const Deviation ab = moved_mesh_deviation(a.positions, b);
  const Deviation ba = moved_mesh_deviation(b.positions, a);
  EXPECT_EQ(ab.hausdorff, ba.hausdorff);
  EXPECT_EQ(ab.mean, ba.mean);
  EXPECT_EQ(ab.p95, ba.p95);
  const Deviation general = mesh_deviation(a, rotated_corners(b));
  EXPECT_GT(general.hausdorff, 0.01);
  EXPECT_NEAR(ab.hausdorff, general.hausdorff, 1e-9);
  EXPECT_NEAR(ab.mean, general.mean, 1e-9 * general.mean);
  EXPECT_NEAR(ab.p95, general.p95, 1e-9 * general.p95);
  // mesh_deviation on shared triangles takes the moved path with every sample measured.
  const Deviation shared = mesh_deviation(a, b);
  EXPECT_EQ(shared.hausdorff, moved_mesh_deviation(a.positions, b, SIZE_MAX).hausdorff);
}

TEST(MovedMeshDeviation, SubsetStatisticsStayCloseAndTheMaximumExact) {
  const TriMesh a = sphere(20, 0.4);
  TriMesh b = a;
  smooth_mesh(b, {.method = SmoothMethod::laplacian, .iterations = 20});
  const Deviation all = moved_mesh_deviation(a.positions, b, SIZE_MAX);
  const size_t samples = a.triangle_count() + a.positions.size();
  ASSERT_GT(samples, size_t{100000});
  const Deviation subset = moved_mesh_deviation(a.positions, b, 1 << 15);
  EXPECT_EQ(subset.hausdorff, all.hausdorff);  // exact whatever the subset
  EXPECT_NEAR(subset.mean, all.mean, 0.01 * all.mean);
  EXPECT_NEAR(subset.p95, all.p95, 0.01 * all.p95);
}

TEST(MovedMeshDeviation, EmptyMeshesDeviateByZero) {
  const Deviation d = moved_mesh_deviation({}, TriMesh{});
  EXPECT_EQ(d.hausdorff, 0);
  EXPECT_EQ(d.mean, 0);
}

// The phantom (at 256 x 256 x 102, the anatomy of the default grid) with the default smoothing:
// the report's numbers per part equal the general path's exact ones: the Hausdorff distance to
// 1e-4 mm, mean and 95th percentile within 1 %.
TEST(MovedMeshDeviation, PhantomPartsMatchTheExactDeviation) {
  const Image image =
      test::label_image(make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4}}));
  ExtractedPositions extracted;
  const Scene scene = build_scene(image, {}, null_progress(), nullptr, &extracted);
  const std::vector<PartMeasures> measures = measure_scene(scene, {.extracted = &extracted}).parts;
  ASSERT_EQ(measures.size(), 10u);
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    TriMesh before = scene.parts[p].mesh;
    before.positions = extracted.parts[p];
    const Deviation exact = mesh_deviation(before, rotated_corners(scene.parts[p].mesh));
    const Deviation fast = *measures[p].smoothing_deviation;
    EXPECT_GT(exact.hausdorff, 0.05) << scene.parts[p].name;
    EXPECT_NEAR(fast.hausdorff, exact.hausdorff, 1e-4) << scene.parts[p].name;
    EXPECT_NEAR(fast.mean, exact.mean, 0.01 * exact.mean) << scene.parts[p].name;
    EXPECT_NEAR(fast.p95, exact.p95, 0.01 * exact.p95) << scene.parts[p].name;
    EXPECT_NEAR(*measures[p].volume_before_mm3, enclosed_volume(before), 1e-9 * enclosed_volume(before));
    ASSERT_TRUE(measures[p].quality.has_value());
    EXPECT_EQ(measures[p].quality->triangles, int64_t(scene.parts[p].mesh.triangle_count()));
    EXPECT_TRUE(measures[p].mesh.closed());
  }
}

TEST(SceneMeasures, RefusesPositionsOfAnotherSceneAndLeavesOutWhatWasNotAsked) {
  Scene scene;
  scene.parts.resize(1);
  scene.parts[0].mesh = sphere(3, 0.9);
  ExtractedPositions wrong;
  wrong.parts.push_back({Vec3f{0, 0, 0}});
  EXPECT_THROW(measure_scene(scene, {.extracted = &wrong}), std::invalid_argument);
  const std::vector<PartMeasures> m = measure_scene(scene, {.quality = false}).parts;
  ASSERT_EQ(m.size(), 1u);
  EXPECT_FALSE(m[0].quality.has_value());
  EXPECT_FALSE(m[0].smoothing_deviation.has_value());
  EXPECT_TRUE(m[0].mesh.closed());
}

}  // namespace
}  // namespace segmesh
