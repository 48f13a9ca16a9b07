// Marching Cubes: the case table's consistency on every configuration, closedness and topology on
// random and adversarial fields, accuracy on analytic shapes, world placement and determinism.
#include "segmesh/marching_cubes.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <random>
#include <set>

#include "segmesh/marching_cubes_table.hpp"
#include "segmesh/mesh_measures.hpp"
#include "support/reference_components.hpp"

namespace segmesh {
namespace {

// A binary field with `pad` background voxels around the given inside pattern.
Volume<uint8_t> padded(const std::array<int64_t, 3>& dims, const std::vector<uint8_t>& inside,
                       int pad = 1) {
  Volume<uint8_t> v;
  v.grid.dims = {dims[0] + 2 * pad, dims[1] + 2 * pad, dims[2] + 2 * pad};
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 0; k < dims[2]; ++k)
    for (int64_t j = 0; j < dims[1]; ++j)
      for (int64_t i = 0; i < dims[0]; ++i)
        v.at(i + pad, j + pad, k + pad) = inside[(k * dims[1] + j) * dims[0] + i];
  return v;
}

// Connected components of voxels with value == `want` under 6/18/26-connectivity.
std::vector<int> label_components(const Volume<uint8_t>& v, uint8_t want, int connectivity,
                                  int& count) {
  return test::reference_components(
      v, connectivity, [want](uint8_t x) { return x == want; },
      [](uint8_t, uint8_t) { return true; }, count);
}

// The background connectivity that pairs with each foreground connectivity in our table.
int paired_background(int connectivity) { return connectivity == 6 ? 18 : 6; }

// In a well-composed pairing every (foreground component, background component) pair that touches
// is separated by exactly one connected surface.
int64_t expected_shells(const Volume<uint8_t>& v, int connectivity) {
  int nf = 0, nb = 0;
  const auto fg = label_components(v, 1, connectivity, nf);
  const auto bg = label_components(v, 0, paired_background(connectivity), nb);
  std::set<std::pair<int, int>> pairs;
  const auto& d = v.grid.dims;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const size_t a = v.grid.index(i, j, k);
        for (int axis = 0; axis < 3; ++axis) {
          const int64_t i1 = i + (axis == 0), j1 = j + (axis == 1), k1 = k + (axis == 2);
          if (i1 >= d[0] || j1 >= d[1] || k1 >= d[2]) continue;
          const size_t b = v.grid.index(i1, j1, k1);
          if (v.voxels[a] == v.voxels[b]) continue;
          pairs.insert(v.voxels[a] ? std::make_pair(fg[a], bg[b]) : std::make_pair(fg[b], bg[a]));
        }
      }
  return static_cast<int64_t>(pairs.size());
}

void expect_closed(const TriMesh& mesh, const std::string& what) {
  const MeshMeasures m = measure_mesh(mesh);
  EXPECT_TRUE(m.closed()) << what << ": boundary " << m.boundary_edges << " non-manifold "
                          << m.nonmanifold_edges << " winding " << m.winding_errors;
  EXPECT_GT(m.volume_mm3, 0) << what;
  EXPECT_EQ(m.degenerate_triangles, 0) << what;
}

TEST(MarchingCubesTable, EveryCaseIsBuiltForEveryConnectivity) {
  for (int c : {6, 18, 26}) {
    const McTable& t = mc_table(c);
    EXPECT_EQ(t.triangle_count(0), 0);
    EXPECT_EQ(t.triangle_count(255), 0);
    for (int cs = 1; cs < 255; ++cs) EXPECT_GT(t.triangle_count(cs), 0) << cs;
    // Complementary cases without ambiguity mirror each other: one inside corner, one triangle.
    EXPECT_EQ(t.triangle_count(1), 1);
    EXPECT_EQ(t.triangle_count(254), 1);
  }
  // Corner-only contact (corners 0 and 7): separate under 6 and 18, a tube under 26.
  EXPECT_EQ(mc_table(6).triangle_count(0x81), 2);
  EXPECT_EQ(mc_table(18).triangle_count(0x81), 2);
  EXPECT_EQ(mc_table(26).triangle_count(0x81), 6);
  // Edge-only contact on a face (corners 0 and 3): separate under 6, joined under 18 and 26.
  EXPECT_EQ(mc_table(6).triangle_count(0x09), 2);
  EXPECT_EQ(mc_table(18).triangle_count(0x09), 4);
  EXPECT_THROW(mc_table(8), std::invalid_argument);
}

TEST(MarchingCubes, AllSingleCellConfigurationsAreClosed) {
  for (int c : {6, 18, 26}) {
    for (int cs = 1; cs < 255; ++cs) {
      std::vector<uint8_t> inside(8);
      for (int k = 0; k < 8; ++k) inside[k] = (cs >> k) & 1;
      const auto field = padded({2, 2, 2}, inside);
      const TriMesh mesh = marching_cubes(field, {.iso = 0.5, .connectivity = c});
      const std::string what = "connectivity " + std::to_string(c) + " case " + std::to_string(cs);
      expect_closed(mesh, what);
      EXPECT_EQ(measure_mesh(mesh).shells, expected_shells(field, c)) << what;
    }
  }
}

TEST(MarchingCubes, AllTwoCellConfigurationsAreClosed) {
  // Two face-adjacent cells share four corners: 12 corners, 4096 configurations, every pairing of
  // ambiguous faces on the shared face included.
  for (int c : {6, 18, 26}) {
    for (int cs = 1; cs < 4095; ++cs) {
      std::vector<uint8_t> inside(12);
      for (int k = 0; k < 12; ++k) inside[k] = (cs >> k) & 1;
      const auto field = padded({3, 2, 2}, inside);
      const TriMesh mesh = marching_cubes(field, {.iso = 0.5, .connectivity = c});
      const MeshMeasures m = measure_mesh(mesh);
      ASSERT_TRUE(m.closed()) << "connectivity " << c << " configuration " << cs;
      ASSERT_GT(m.volume_mm3, 0);
      ASSERT_EQ(m.shells, expected_shells(field, c)) << "connectivity " << c << " config " << cs;
    }
  }
}

TEST(MarchingCubes, RandomAndCheckerboardFieldsAreClosedWithOneShellPerBoundary) {
  std::mt19937 rng(42);
  for (int c : {6, 18, 26}) {
    for (double density : {0.2, 0.5, 0.8}) {
      std::bernoulli_distribution coin(density);
      std::vector<uint8_t> inside(14 * 13 * 12);
      for (auto& v : inside) v = coin(rng);
      const auto field = padded({14, 13, 12}, inside);
      const TriMesh mesh = marching_cubes(field, {.iso = 0.5, .connectivity = c});
      const std::string what = "random, connectivity " + std::to_string(c);
      expect_closed(mesh, what);
      EXPECT_EQ(measure_mesh(mesh).shells, expected_shells(field, c)) << what;
    }
    std::vector<uint8_t> checker(9 * 9 * 9);
    for (int k = 0; k < 9; ++k)
      for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i) checker[(k * 9 + j) * 9 + i] = (i + j + k) % 2;
    const auto field = padded({9, 9, 9}, checker);
    const TriMesh mesh = marching_cubes(field, {.iso = 0.5, .connectivity = c});
    expect_closed(mesh, "checkerboard, connectivity " + std::to_string(c));
    EXPECT_EQ(measure_mesh(mesh).shells, expected_shells(field, c));
  }
}

TEST(MarchingCubes, IsoEqualToCornerValuesGivesNoDegenerateTriangles) {
  // Integer values at an integer iso: vertices would fall onto the corners and collapse.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> value(0, 2);
  Volume<int32_t> v;
  v.grid.dims = {16, 15, 14};
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 1; k < 13; ++k)
    for (int64_t j = 1; j < 14; ++j)
      for (int64_t i = 1; i < 15; ++i) v.at(i, j, k) = value(rng);
  for (int c : {6, 18, 26}) {
    const TriMesh mesh = marching_cubes(v, {.iso = 1.0, .connectivity = c});
    expect_closed(mesh, "iso on corner values, connectivity " + std::to_string(c));
  }
}

// A signed field sampled on an anisotropic grid: value = shape(world point), inside positive.
template <class F>
Volume<float> sample(const Grid& grid, F&& shape) {
  Volume<float> v;
  v.grid = grid;
  v.voxels.resize(grid.voxel_count());
  for (int64_t k = 0; k < grid.dims[2]; ++k)
    for (int64_t j = 0; j < grid.dims[1]; ++j)
      for (int64_t i = 0; i < grid.dims[0]; ++i)
        v.at(i, j, k) = static_cast<float>(shape(grid.to_world({double(i), double(j), double(k)})));
  return v;
}

Grid anisotropic_grid(double extent, Mat3d direction = identity3()) {
  Grid g;
  g.spacing = {0.25, 0.3, 0.45};
  g.direction = direction;
  for (int a = 0; a < 3; ++a) g.dims[a] = static_cast<int64_t>(2 * extent / g.spacing[a]) + 1;
  // Centre the grid on the world origin.
  const Vec3d half = g.to_world({double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2,
                                 double(g.dims[2] - 1) / 2});
  g.origin = {-half.x, -half.y, -half.z};
  return g;
}

double max_normal_angle_deg(const TriMesh& mesh, auto&& analytic_normal) {
  double worst = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3d n = to_double(mesh.normals[v]);
    const Vec3d a = analytic_normal(to_double(mesh.positions[v]));
    const double c = std::clamp(dot(n, a) / (norm(n) * norm(a)), -1.0, 1.0);
    worst = std::max(worst, std::acos(c) * 180 / std::numbers::pi);
  }
  return worst;
}

TEST(MarchingCubes, SphereOnAnisotropicGridMatchesAnalyticAreaVolumeAndNormals) {
  const double r = 10;
  const Grid grid = anisotropic_grid(r + 2);
  const auto field = sample(grid, [&](Vec3d p) { return r - norm(p); });
  for (auto normals : {NormalMethod::central, NormalMethod::sobel}) {
    const TriMesh mesh = marching_cubes(field, {.iso = 0, .normals = normals});
    const MeshMeasures m = measure_mesh(mesh);
    EXPECT_TRUE(m.closed());
    EXPECT_EQ(m.euler, 2);
    EXPECT_NEAR(m.volume_mm3, 4.0 / 3.0 * std::numbers::pi * r * r * r,
                0.01 * 4.0 / 3.0 * std::numbers::pi * r * r * r);
    EXPECT_NEAR(m.area_mm2, 4 * std::numbers::pi * r * r, 0.01 * 4 * std::numbers::pi * r * r);
    EXPECT_LT(max_normal_angle_deg(mesh, [](Vec3d p) { return p; }), 5.0);
  }
}

TEST(MarchingCubes, TorusOnAnisotropicGridMatchesAnalyticAreaVolumeAndNormals) {
  const double big = 9, small = 3.5;
  const Grid grid = anisotropic_grid(big + small + 2);
  auto torus = [&](Vec3d p) {
    const double q = std::hypot(p.x, p.y) - big;
    return small - std::hypot(q, p.z);
  };
  const auto field = sample(grid, torus);
  const TriMesh mesh = marching_cubes(field, {.iso = 0});
  const MeshMeasures m = measure_mesh(mesh);
  const double pi = std::numbers::pi;
  EXPECT_TRUE(m.closed());
  EXPECT_EQ(m.euler, 0);
  EXPECT_EQ(m.shells, 1);
  EXPECT_NEAR(m.volume_mm3, 2 * pi * pi * big * small * small, 0.01 * 2 * pi * pi * big * small * small);
  EXPECT_NEAR(m.area_mm2, 4 * pi * pi * big * small, 0.01 * 4 * pi * pi * big * small);
  EXPECT_LT(max_normal_angle_deg(mesh,
                                 [&](Vec3d p) {
                                   const double rho = std::hypot(p.x, p.y);
                                   const Vec3d centre{p.x * big / rho, p.y * big / rho, 0};
                                   return p - centre;
                                 }),
            5.0);
}

TEST(MarchingCubes, MirroredAndRotatedGridsKeepOutwardWindingAndWorldPlacement) {
  const double r = 6;
  const double c = std::cos(0.5), s = std::sin(0.5);
  // A rotation about z followed by a mirror of the x axis: determinant -1.
  const Mat3d mirrored{-c, -s, 0, -s, c, 0, 0, 0, 1};
  ASSERT_LT(determinant(mirrored), 0);
  const Vec3d centre{3, -4, 5};
  Grid grid = anisotropic_grid(r + 2, mirrored);
  grid.origin = {grid.origin[0] + centre.x, grid.origin[1] + centre.y, grid.origin[2] + centre.z};
  const auto field = sample(grid, [&](Vec3d p) { return r - norm(p - centre); });
  const TriMesh mesh = marching_cubes(field, {.iso = 0});
  const MeshMeasures m = measure_mesh(mesh);
  EXPECT_TRUE(m.closed());
  EXPECT_NEAR(m.volume_mm3, 4.0 / 3.0 * std::numbers::pi * r * r * r, 0.02 * 4.0 / 3.0 * std::numbers::pi * r * r * r);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3d p = to_double(mesh.positions[v]);
    ASSERT_NEAR(norm(p - centre), r, 0.1);
    ASSERT_GT(dot(to_double(mesh.normals[v]), p - centre), 0) << "normal points inwards";
  }
}

TEST(MarchingCubes, OutputIsIdenticalForAnyThreadCount) {
  std::mt19937 rng(3);
  std::bernoulli_distribution coin(0.5);
  std::vector<uint8_t> inside(40 * 30 * 50);
  for (auto& v : inside) v = coin(rng);
  auto field = padded({40, 30, 50}, inside);
  field.grid.spacing = {0.5, 0.5, 2};
  TriMesh one, many;
  tbb::task_arena(1).execute([&] { one = marching_cubes(field, {}); });
  tbb::task_arena(4).execute([&] { many = marching_cubes(field, {}); });
  ASSERT_EQ(one.indices, many.indices);
  ASSERT_EQ(one.positions.size(), many.positions.size());
  EXPECT_EQ(0, std::memcmp(one.positions.data(), many.positions.data(),
                           one.positions.size() * sizeof(Vec3f)));
  EXPECT_EQ(0, std::memcmp(one.normals.data(), many.normals.data(),
                           one.normals.size() * sizeof(Vec3f)));
}

TEST(MarchingCubes, EmptyAndFullFieldsGiveNoTriangles) {
  Volume<uint8_t> v;
  v.grid.dims = {4, 4, 4};
  v.voxels.assign(64, 0);
  EXPECT_TRUE(marching_cubes(v, {}).empty());
  v.voxels.assign(64, 1);
  EXPECT_TRUE(marching_cubes(v, {}).empty());
  v.grid.dims = {1, 4, 4};
  v.voxels.assign(16, 1);
  EXPECT_TRUE(marching_cubes(v, {}).empty());
}

}  // namespace
}  // namespace segmesh
