// Triangle quality: the radii ratio on triangles of known shape and against an independent
// formula, the statistics of a hand-made mesh, per-vertex worst quality, the colour ramp, and
// thread-count independence.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "segmesh/quality.hpp"

namespace segmesh {
namespace {

// rho = 8 (s-a)(s-b)(s-c) / (abc) = 8 Area^2 / (s abc) = 4 |n|^2 / (perimeter abc), n the cross
// product of two edges: independent of the library's edge-length arrangement, in long double.
long double reference_rho(Vec3d a, Vec3d b, Vec3d c) {
  auto len = [](Vec3d u, Vec3d v) {
    const long double x = (long double)u.x - v.x, y = (long double)u.y - v.y,
                      z = (long double)u.z - v.z;
    return std::sqrt(x * x + y * y + z * z);
  };
  const long double ux = (long double)b.x - a.x, uy = (long double)b.y - a.y,
                    uz = (long double)b.z - a.z;
  const long double vx = (long double)c.x - a.x, vy = (long double)c.y - a.y,
                    vz = (long double)c.z - a.z;
  const long double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  const long double la = len(b, c), lb = len(c, a), lc = len(a, b);
  return 4 * (nx * nx + ny * ny + nz * nz) / ((la + lb + lc) * la * lb * lc);
}

// Appends a triangle with its own three vertices.
void add_triangle(TriMesh& mesh, Vec3f a, Vec3f b, Vec3f c) {
  const auto first = static_cast<uint32_t>(mesh.positions.size());
  mesh.positions.insert(mesh.positions.end(), {a, b, c});
  mesh.indices.insert(mesh.indices.end(), {first, first + 1, first + 2});
}

TEST(QualityRadiiRatio, EquilateralIsOne) {
  EXPECT_NEAR(radii_ratio({1, 0, 0}, {0, 1, 0}, {0, 0, 1}), 1.0, 1e-12);
  EXPECT_NEAR(radii_ratio({0, 0, 0}, {2, 0, 0}, {1, std::sqrt(3.0), 0}), 1.0, 1e-12);
  // Far from the origin and small: the result depends on the shape only.
  const Vec3d o{512.25, -310.5, 1200};
  EXPECT_NEAR(radii_ratio(o + Vec3d{0.1, 0, 0}, o + Vec3d{0, 0.1, 0}, o + Vec3d{0, 0, 0.1}), 1.0,
              1e-12);
}

TEST(QualityRadiiRatio, DegenerateIsZero) {
  EXPECT_EQ(radii_ratio({0, 0, 0}, {1, 0, 0}, {3, 0, 0}), 0.0);  // collinear, outer corner
  EXPECT_EQ(radii_ratio({0, 0, 0}, {3, 0, 0}, {1, 0, 0}), 0.0);  // collinear, corner between
  EXPECT_NEAR(radii_ratio({0, 0, 0}, {1, 1, 1}, {3, 3, 3}), 0.0, 1e-12);  // skew line
  EXPECT_EQ(radii_ratio({1, 2, 3}, {1, 2, 3}, {4, 5, 7}), 0.0);           // two equal points
  EXPECT_EQ(radii_ratio({4, 5, 7}, {1, 2, 3}, {1, 2, 3}), 0.0);
  EXPECT_EQ(radii_ratio({1, 2, 3}, {1, 2, 3}, {1, 2, 3}), 0.0);  // all equal
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(radii_ratio({nan, 0, 0}, {1, 0, 0}, {0, 1, 0}), 0.0);
}

TEST(QualityRadiiRatio, RightIsoscelesIsTwoRootTwoMinusOne) {
  const double expected = 2 * (std::sqrt(2.0) - 1);
  EXPECT_NEAR(radii_ratio({0, 0, 0}, {1, 0, 0}, {0, 1, 0}), expected, 1e-12);
  EXPECT_NEAR(radii_ratio({5, 5, 5}, {5, 5, 8}, {5, 8, 5}), expected, 1e-12);
  // 30-60-90: sqrt(3) - 1.
  EXPECT_NEAR(radii_ratio({0, 0, 0}, {1, 0, 0}, {0, std::sqrt(3.0), 0}), std::sqrt(3.0) - 1, 1e-12);
}

TEST(QualityRadiiRatio, MatchesAreaFormulaOnRandomAndNeedleTriangles) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int i = 0; i < 10000; ++i) {
    const Vec3d a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)}, c{u(rng), u(rng), u(rng)};
    const double rho = radii_ratio(a, b, c);
    ASSERT_NEAR(rho, double(reference_rho(a, b, c)), 1e-12) << i;
    // Any corner order gives the same value.
    ASSERT_NEAR(radii_ratio(b, c, a), rho, 1e-14);
    ASSERT_NEAR(radii_ratio(c, b, a), rho, 1e-14);
  }
  // Needles: a thin isosceles triangle and a thin one with a short edge, relative accuracy.
  for (double h : {1e-2, 1e-3, 1e-4}) {
    const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0.5, h, 0}, d{1 + h, h, 0};
    EXPECT_NEAR(radii_ratio(a, b, c) / double(reference_rho(a, b, c)), 1.0, 1e-6) << h;
    EXPECT_NEAR(radii_ratio(a, b, d) / double(reference_rho(a, b, d)), 1.0, 1e-6) << h;
  }
}

TEST(QualityStats, HandMadeMeshHasKnownMinMeanPercentileAndHistogram) {
  // Corner coordinates exactly representable as floats, so every rho is known in closed form.
  const double equilateral = 1.0;                 // (1,0,0) (0,1,0) (0,0,1)
  const double right = 2 * (std::sqrt(2.0) - 1);  // legs 1 and 1
  const double two_one = 6 / std::sqrt(5.0) - 2;  // legs 2 and 1
  TriMesh mesh;
  float x = 0;
  for (int i = 0; i < 50; ++i, x += 3) add_triangle(mesh, {x + 1, 0, 0}, {x, 1, 0}, {x, 0, 1});
  for (int i = 0; i < 48; ++i, x += 3) add_triangle(mesh, {x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0});
  add_triangle(mesh, {x, 0, 0}, {x + 2, 0, 0}, {x, 1, 0});
  x += 3;
  add_triangle(mesh, {x, 0, 0}, {x + 1, 0, 0}, {x + 2, 0, 0});  // degenerate
  ASSERT_EQ(mesh.triangle_count(), 100u);

  const QualityStats s = triangle_quality(mesh);
  EXPECT_EQ(s.triangles, 100);
  EXPECT_EQ(s.min, 0.0);
  EXPECT_NEAR(s.mean, (50 * equilateral + 48 * right + two_one + 0) / 100, 1e-12);
  // numpy.percentile(rho, 1): rank 0.99 between the sorted values 0 and two_one.
  EXPECT_NEAR(s.p01, 0.99 * two_one, 1e-12);
  const std::array<int64_t, 10> expected{1, 0, 0, 0, 0, 0, 1, 0, 48, 50};
  EXPECT_EQ(s.histogram, expected);
  EXPECT_EQ(std::accumulate(s.histogram.begin(), s.histogram.end(), int64_t{0}), s.triangles);
}

TEST(QualityStats, PercentileFollowsNumpyLinearInterpolation) {
  std::vector<double> v{5, 1, 4, 2, 3};
  EXPECT_DOUBLE_EQ(percentile(v, 0.0), 1);
  EXPECT_DOUBLE_EQ(percentile(v, 1.0), 5);
  EXPECT_DOUBLE_EQ(percentile(v, 0.5), 3);
  EXPECT_DOUBLE_EQ(percentile(v, 0.1), 1.4);   // numpy.percentile([1..5], 10) == 1.4
  EXPECT_DOUBLE_EQ(percentile(v, 0.95), 4.8);  // numpy.percentile([1..5], 95) == 4.8
  std::vector<double> one{7};
  EXPECT_EQ(percentile(one, 0.01), 7);
  std::vector<double> none;
  EXPECT_EQ(percentile(none, 0.5), 0);
}

TEST(QualityStats, EmptyMeshGivesZeros) {
  const QualityStats s = triangle_quality(TriMesh{});
  EXPECT_EQ(s.triangles, 0);
  EXPECT_EQ(s.min, 0);
  EXPECT_EQ(s.mean, 0);
  EXPECT_EQ(s.p01, 0);
  EXPECT_EQ(s.histogram, (std::array<int64_t, 10>{}));
}

// Many random triangles sharing random vertices: varied quality and vertex valences.
TriMesh random_mesh(size_t vertices, size_t triangles, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-50, 50);
  std::uniform_int_distribution<uint32_t> pick(0, static_cast<uint32_t>(vertices - 1));
  TriMesh mesh;
  for (size_t v = 0; v < vertices; ++v) mesh.positions.push_back({u(rng), u(rng), u(rng)});
  for (size_t t = 0; t < 3 * triangles; ++t) mesh.indices.push_back(pick(rng));
  return mesh;
}

TEST(QualityStats, LargeMeshStatisticsMatchASerialComputation) {
  const TriMesh mesh = random_mesh(30000, 100000, 5);
  const QualityStats s = triangle_quality(mesh);
  std::vector<double> rho;
  long double sum = 0;
  std::array<int64_t, 10> histogram{};
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const auto* v = &mesh.indices[3 * t];
    rho.push_back(radii_ratio(to_double(mesh.positions[v[0]]), to_double(mesh.positions[v[1]]),
                              to_double(mesh.positions[v[2]])));
    sum += rho.back();
    ++histogram[std::min(9, static_cast<int>(rho.back() * 10))];
  }
  std::sort(rho.begin(), rho.end());
  EXPECT_EQ(s.triangles, 100000);
  EXPECT_EQ(s.min, rho.front());
  EXPECT_NEAR(s.mean, double(sum / rho.size()), 1e-12);
  const double index = 0.01 * (rho.size() - 1);
  const size_t lo = static_cast<size_t>(index);
  EXPECT_NEAR(s.p01, rho[lo] + (index - lo) * (rho[lo + 1] - rho[lo]), 1e-15);
  EXPECT_EQ(s.histogram, histogram);
}

TEST(QualityVertex, TakesTheWorstIncidentTriangleAndOneForUnusedVertices) {
  TriMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0},
                    {0, 1, 0},                         // right isosceles (0, 1, 2)
                    {2, 0, 0}, {1.5f, 0.8660254f, 0},  // near-equilateral (1, 3, 4)
                    {9, 9, 9},                         // unused
                    {0, 2, 0}, {0, 3, 0}};             // collinear with 2: (2, 6, 7)
  mesh.indices = {0, 1, 2, 1, 3, 4, 2, 6, 7};
  auto rho = [&](uint32_t a, uint32_t b, uint32_t c) {
    return static_cast<float>(radii_ratio(
        to_double(mesh.positions[a]), to_double(mesh.positions[b]), to_double(mesh.positions[c])));
  };
  const float right = rho(0, 1, 2), equi = rho(1, 3, 4);
  ASSERT_LT(right, equi);
  ASSERT_GT(equi, 0.999f);
  const std::vector<float> q = vertex_quality(mesh);
  ASSERT_EQ(q.size(), mesh.positions.size());
  EXPECT_EQ(q[0], right);
  EXPECT_EQ(q[1], right);  // shared by the right and the equilateral triangle
  EXPECT_EQ(q[2], 0.0f);   // shared by the right and the degenerate triangle
  EXPECT_EQ(q[3], equi);
  EXPECT_EQ(q[4], equi);
  EXPECT_EQ(q[5], 1.0f);
  EXPECT_EQ(q[6], 0.0f);
  EXPECT_EQ(q[7], 0.0f);
}

TEST(QualityColors, BlueToGreenRamp) {
  const std::vector<Rgba8> c =
      quality_colors({0.0f, 1.0f, 0.5f, -1.0f, 2.0f, std::numeric_limits<float>::quiet_NaN()});
  ASSERT_EQ(c.size(), 6u);
  EXPECT_EQ(c[0], (Rgba8{0, 0, 255, 255}));
  EXPECT_EQ(c[1], (Rgba8{0, 255, 0, 255}));
  EXPECT_EQ(c[2], (Rgba8{0, 128, 127, 255}));
  EXPECT_EQ(c[3], (Rgba8{0, 0, 255, 255}));
  EXPECT_EQ(c[4], (Rgba8{0, 255, 0, 255}));
  EXPECT_EQ(c[5], (Rgba8{0, 0, 255, 255}));
  EXPECT_TRUE(quality_colors({}).empty());
}

TEST(QualityStats, IdenticalForAnyThreadCount) {
  const TriMesh mesh = random_mesh(200000, 600000, 9);
  QualityStats one, many;
  std::vector<float> vq_one, vq_many;
  tbb::task_arena(1).execute([&] {
    one = triangle_quality(mesh);
    vq_one = vertex_quality(mesh);
  });
  tbb::task_arena(4).execute([&] {
    many = triangle_quality(mesh);
    vq_many = vertex_quality(mesh);
  });
  EXPECT_EQ(one.triangles, many.triangles);
  EXPECT_EQ(one.min, many.min);
  EXPECT_EQ(one.mean, many.mean);  // bitwise: the block sums are combined in a fixed order
  EXPECT_EQ(one.p01, many.p01);
  EXPECT_EQ(one.histogram, many.histogram);
  EXPECT_EQ(vq_one, vq_many);
}

}  // namespace
}  // namespace segmesh
