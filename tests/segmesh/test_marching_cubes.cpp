// Marching Cubes: the case table's consistency on every configuration, closedness and topology on
// random and adversarial fields, accuracy on analytic shapes, world placement and determinism.
#include "segmesh/marching_cubes.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <numbers>
#include <random>
#include <set>

#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/mesh_measures.hpp"
#include "support/reference_components.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

using test::anisotropic_grid;
using test::padded;
using test::sample;

const char* normals_label(NormalMethod normals) {
  return normals == NormalMethod::sobel ? "sobel normals" : "central normals";
}

void expect_closed(const TriMesh& mesh, const std::string& what) {
  const MeshMeasures m = measure_mesh(mesh);
  EXPECT_TRUE(m.closed()) << what << ": boundary " << m.boundary_edges << " non-manifold "
                          << m.nonmanifold_edges << " winding " << m.winding_errors;
  EXPECT_EQ(m.nonmanifold_vertices, 0) << what << ": non-manifold vertices (pinch points)";
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
      EXPECT_EQ(measure_mesh(mesh).shells, test::expected_shells(field, c)) << what;
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
      ASSERT_EQ(m.nonmanifold_vertices, 0) << "connectivity " << c << " configuration " << cs;
      ASSERT_GT(m.volume_mm3, 0);
      ASSERT_EQ(m.shells, test::expected_shells(field, c)) << "connectivity " << c << " config " << cs;
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
      EXPECT_EQ(measure_mesh(mesh).shells, test::expected_shells(field, c)) << what;
    }
    std::vector<uint8_t> checker(9 * 9 * 9);
    for (int k = 0; k < 9; ++k)
      for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 9; ++i) checker[(k * 9 + j) * 9 + i] = (i + j + k) % 2;
    const auto field = padded({9, 9, 9}, checker);
    const TriMesh mesh = marching_cubes(field, {.iso = 0.5, .connectivity = c});
    expect_closed(mesh, "checkerboard, connectivity " + std::to_string(c));
    EXPECT_EQ(measure_mesh(mesh).shells, test::expected_shells(field, c));
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
    EXPECT_TRUE(m.closed()) << "sphere, " << normals_label(normals);
    EXPECT_EQ(m.nonmanifold_vertices, 0) << "sphere, " << normals_label(normals);
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
  EXPECT_TRUE(m.closed()) << "torus";
  EXPECT_EQ(m.nonmanifold_vertices, 0) << "torus";
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
  EXPECT_TRUE(m.closed()) << "mirrored sphere";
  EXPECT_EQ(m.nonmanifold_vertices, 0) << "mirrored sphere";
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
  ASSERT_FALSE(one.normals.empty());
  EXPECT_TRUE(test::identical(one, many));
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

TEST(MarchingCubes, WithoutNormalsTheSameSurfaceAndNoNormals) {
  std::mt19937 rng(5);
  std::bernoulli_distribution coin(0.4);
  std::vector<uint8_t> inside(20 * 24 * 16);
  for (auto& v : inside) v = coin(rng);
  auto field = padded({20, 24, 16}, inside);
  field.grid.spacing = {0.7, 0.5, 2};
  const TriMesh with = marching_cubes(field, {});
  const TriMesh without = marching_cubes(field, {.vertex_normals = false});
  ASSERT_FALSE(with.empty());
  EXPECT_TRUE(without.normals.empty());
  TriMesh surface = with;
  surface.normals.clear();
  EXPECT_TRUE(test::identical(surface, without));
}

}  // namespace
}  // namespace segmesh

// The extractors keep per-row counts and first ids in 32 bits, like the vertex ids; a surface
// past that is refused with a message that names the extractor and says what to do.
TEST(MeshIdCount, KeepsCountsUpTo32BitsAndRefusesMoreNamingTheExtractor) {
  EXPECT_EQ(segmesh::mesh_id_count(0, "marching cubes"), 0u);
  EXPECT_EQ(segmesh::mesh_id_count(0xffffffffull, "marching cubes"), 0xffffffffu);
  try {
    segmesh::mesh_id_count(0x100000000ull, "dual contouring");
    FAIL() << "no error for 2^32";
  } catch (const segmesh::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "dual contouring: the surface has more than 4 billion vertices or triangles; crop "
              "the volume or select fewer labels");
  }
}
