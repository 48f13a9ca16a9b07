// Point-triangle and point-mesh distances against independent references, and the symmetric
// deviation between meshes on shapes whose answer is known.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- an independent point-triangle distance, in long double ----------------------------------
// Not Ericson's region walk: project onto the plane and keep the projection when it is inside all
// three edges, else take the nearest of the three segments. Degenerate triangles: segments only.

struct V {
  long double x, y, z;
};
V lv(Vec3d p) {
  return {p.x, p.y, p.z};
}
V operator-(V a, V b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V operator+(V a, V b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V operator*(long double s, V a) {
  return {s * a.x, s * a.y, s * a.z};
}
long double ldot(V a, V b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V lcross(V a, V b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

long double segment_distance(V p, V a, V b) {
  const V ab = b - a;
  const long double len2 = ldot(ab, ab);
  const long double t = len2 > 0 ? std::clamp(ldot(p - a, ab) / len2, 0.0L, 1.0L) : 0.0L;
  const V d = p - (a + t * ab);
  return std::sqrt(ldot(d, d));
}

long double reference_distance(Vec3d pd, Vec3d ad, Vec3d bd, Vec3d cd, bool degenerate) {
  const V p = lv(pd), a = lv(ad), b = lv(bd), c = lv(cd);
  const long double edges =
      std::min({segment_distance(p, a, b), segment_distance(p, b, c), segment_distance(p, c, a)});
  if (degenerate) return edges;
  const V n = lcross(b - a, c - a);
  const long double nn = ldot(n, n);
  const V q = p - (ldot(p - a, n) / nn) * n;
  const bool inside = ldot(lcross(b - a, q - a), n) >= 0 && ldot(lcross(c - b, q - b), n) >= 0 &&
                      ldot(lcross(a - c, q - c), n) >= 0;
  if (!inside) return edges;
  const V d = p - q;
  return std::sqrt(ldot(d, d));
}

double dist(Vec3d p, Vec3d q) {
  return norm(p - q);
}

// ---- meshes ----------------------------------------------------------------------------------

// A closed sphere of radius r around `centre` from Marching Cubes on a sampled signed distance.
TriMesh sphere(double r, double spacing, Vec3d centre = {}) {
  Volume<float> field;
  const auto n = static_cast<int64_t>(2 * (r + 2) / spacing) + 1;
  field.grid.dims = {n, n, n};
  field.grid.spacing = {spacing, spacing, spacing};
  const double half = spacing * double(n - 1) / 2;
  field.grid.origin = {centre.x - half, centre.y - half, centre.z - half};
  field.voxels.resize(field.grid.voxel_count());
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i)
        field.at(i, j, k) = static_cast<float>(
            r - norm(field.grid.to_world({double(i), double(j), double(k)}) - centre));
  return marching_cubes(field, {.iso = 0});
}

// The closed cube [0, side]^3 + offset, 8 vertices and 12 triangles wound outwards.
TriMesh cube(float side, Vec3f offset = {}) {
  TriMesh m;
  for (int v = 0; v < 8; ++v)
    m.positions.push_back({offset.x + side * (v & 1), offset.y + side * ((v >> 1) & 1),
                           offset.z + side * ((v >> 2) & 1)});
  m.indices = {0, 2, 1, 1, 2, 3,   // z = 0
               4, 5, 6, 5, 7, 6,   // z = side
               0, 1, 4, 1, 5, 4,   // y = 0
               2, 6, 3, 3, 6, 7,   // y = side
               0, 4, 2, 2, 4, 6,   // x = 0
               1, 3, 5, 3, 7, 5};  // x = side
  return m;
}

double brute_force_distance(const TriMesh& mesh, Vec3d p) {
  double best = kInf;
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec3d q = closest_point_on_triangle(p, to_double(mesh.positions[mesh.indices[3 * t]]),
                                              to_double(mesh.positions[mesh.indices[3 * t + 1]]),
                                              to_double(mesh.positions[mesh.indices[3 * t + 2]]));
    best = std::min(best, dist(p, q));
  }
  return best;
}

// The deviation by its definition, for the references: every sample of both meshes (the
// vertices, the triangles' centroids) measured with distance(to, point).
template <class Distance>
Deviation every_sample_deviation(const TriMesh& a, const TriMesh& b, Distance&& distance) {
  std::vector<double> d;
  auto samples = [&](const TriMesh& from, const TriMesh& to) {
    for (const Vec3f& v : from.positions) d.push_back(distance(to, to_double(v)));
    for (size_t t = 0; t < from.triangle_count(); ++t) {
      const Vec3d c = (1.0 / 3.0) * (to_double(from.positions[from.indices[3 * t]]) +
                                     to_double(from.positions[from.indices[3 * t + 1]]) +
                                     to_double(from.positions[from.indices[3 * t + 2]]));
      d.push_back(distance(to, c));
    }
  };
  samples(a, b);
  samples(b, a);
  std::sort(d.begin(), d.end());
  double sum = 0;
  for (double x : d) sum += x;
  const double index = 0.95 * double(d.size() - 1);
  const auto lo = static_cast<size_t>(index);
  return {d.back(), sum / double(d.size()), d[lo] + (index - double(lo)) * (d[lo + 1] - d[lo])};
}

Vec3d random_unit(std::mt19937& rng) {
  std::normal_distribution<double> g;
  const Vec3d v{g(rng), g(rng), g(rng)};
  return (1 / norm(v)) * v;
}

// ---- point to triangle -----------------------------------------------------------------------

TEST(MeshDistanceSegment, ClosestPointOnSegmentAndOnAPoint) {
  EXPECT_EQ(dist(closest_point_on_segment({0.5, 2, 0}, {0, 0, 0}, {1, 0, 0}), {0.5, 0, 0}), 0);
  EXPECT_EQ(dist(closest_point_on_segment({-3, 1, 0}, {0, 0, 0}, {1, 0, 0}), {0, 0, 0}), 0);
  EXPECT_EQ(dist(closest_point_on_segment({7, 1, 0}, {0, 0, 0}, {1, 0, 0}), {1, 0, 0}), 0);
  EXPECT_EQ(dist(closest_point_on_segment({7, 1, 0}, {2, 2, 2}, {2, 2, 2}), {2, 2, 2}), 0);
}

TEST(MeshDistanceTriangle, MatchesIndependentReferenceOnRandomTrianglesAndPoints) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<double> scale(0.01, 100);
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    const double s = scale(rng);
    const Vec3d o{300 * u(rng), 300 * u(rng), 300 * u(rng)};
    const Vec3d a = o + s * Vec3d{u(rng), u(rng), u(rng)};
    const Vec3d b = o + s * Vec3d{u(rng), u(rng), u(rng)};
    const Vec3d c = o + s * Vec3d{u(rng), u(rng), u(rng)};
    for (int j = 0; j < 20; ++j) {
      // Near (inside the triangle's box and around it) and far (up to 1000 sizes away).
      const double reach = j < 15 ? 2 * s : 1000 * s;
      const Vec3d p = o + reach * Vec3d{u(rng), u(rng), u(rng)};
      const Vec3d q = closest_point_on_triangle(p, a, b, c);
      const double expected = double(reference_distance(p, a, b, c, false));
      // Relative to the distances involved, plus the rounding of coordinates up to 300.
      const double tolerance = 1e-12 * (s + norm(p - o)) + 1e-13 * norm(o);
      ASSERT_NEAR(dist(p, q), expected, tolerance) << i << " " << j;
      // The returned point lies on the triangle.
      ASSERT_NEAR(double(reference_distance(q, a, b, c, false)), 0, tolerance);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 60000);
}

TEST(MeshDistanceTriangle, EveryVoronoiRegionGivesItsFeature) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  std::uniform_real_distribution<double> pos(0.05, 3);
  std::uniform_real_distribution<double> frac(0.05, 0.95);
  for (int i = 0; i < 2000; ++i) {
    const Vec3d v[3] = {
        {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng)}};
    const Vec3d n = cross(v[1] - v[0], v[2] - v[0]);
    if (norm(n) < 0.05) continue;  // keep the regions well apart for this test
    const Vec3d nh = (1 / norm(n)) * n;
    const double h = u(rng);  // height above or below the plane, either side
    for (int k = 0; k < 3; ++k) {
      const Vec3d a = v[k], b = v[(k + 1) % 3], c = v[(k + 2) % 3];
      const Vec3d ab = (1 / norm(b - a)) * (b - a), ac = (1 / norm(c - a)) * (c - a);
      // Vertex region of a: a + (a direction with non-positive dot with both edges) + height.
      const Vec3d out_a = -1.0 * (ab + ac);
      const Vec3d pa = a + pos(rng) * out_a + h * nh;
      EXPECT_LT(dist(closest_point_on_triangle(pa, v[0], v[1], v[2]), a), 1e-12) << i;
      // Edge region of ab: a point of the edge + the in-plane outward normal of the edge + height.
      Vec3d out_ab = cross(b - a, nh);
      if (dot(out_ab, c - a) > 0) out_ab = -1.0 * out_ab;
      out_ab = (1 / norm(out_ab)) * out_ab;
      const Vec3d foot = a + frac(rng) * (b - a);
      const Vec3d pe = foot + pos(rng) * out_ab + h * nh;
      EXPECT_LT(dist(closest_point_on_triangle(pe, v[0], v[1], v[2]), foot), 1e-12) << i;
      EXPECT_NEAR(norm(pe - closest_point_on_triangle(pe, v[0], v[1], v[2])), norm(pe - foot),
                  1e-12);
    }
    // Face region, both sides: a convex combination + height.
    double w0 = frac(rng), w1 = frac(rng), w2 = frac(rng);
    const double sum = w0 + w1 + w2;
    const Vec3d inside = (w0 / sum) * v[0] + (w1 / sum) * v[1] + (w2 / sum) * v[2];
    for (double side : {-1.0, 1.0}) {
      const Vec3d pf = inside + side * std::abs(h) * nh;
      const Vec3d q = closest_point_on_triangle(pf, v[0], v[1], v[2]);
      EXPECT_LT(dist(q, inside), 1e-12) << i;
      EXPECT_NEAR(dist(pf, q), std::abs(h), 1e-12);
    }
  }
}

TEST(MeshDistanceTriangle, DegenerateTrianglesAreSegmentsOrPoints) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 2000; ++i) {
    const Vec3d a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
    const double t = 3 * u(rng);  // the third corner anywhere on the line: between or beyond
    const Vec3d on_line = a + t * (b - a);
    const Vec3d shapes[4][3] = {{a, b, on_line}, {on_line, a, b}, {a, a, b}, {a, a, a}};
    for (const auto& tri : shapes) {
      for (int j = 0; j < 10; ++j) {
        const Vec3d p{3 * u(rng), 3 * u(rng), 3 * u(rng)};
        const Vec3d q = closest_point_on_triangle(p, tri[0], tri[1], tri[2]);
        ASSERT_TRUE(std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z));
        ASSERT_NEAR(dist(p, q), double(reference_distance(p, tri[0], tri[1], tri[2], true)), 1e-12)
            << i;
      }
    }
  }
  // Points exactly at the corners of a degenerate triangle.
  EXPECT_EQ(dist(closest_point_on_triangle({1, 2, 3}, {1, 2, 3}, {1, 2, 3}, {4, 5, 6}), {1, 2, 3}),
            0);
  EXPECT_EQ(dist(closest_point_on_triangle({4, 5, 6}, {1, 2, 3}, {1, 2, 3}, {4, 5, 6}), {4, 5, 6}),
            0);
}

TEST(MeshDistanceTriangle, NeedleTrianglesOnBothSidesOfTheFlatnessLimit) {
  // Three thin shapes (a needle, a flat cap with its obtuse corner first, a short edge) at
  // thickness 1e-6 (region walk), 1e-10 and 1e-14 (taken as segments; the region walk would be off
  // by up to 1e-3 at 1e-14): all within 1e-8 of the triangle's size of the exact distance.
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double thin : {1e-6, 1e-10, 1e-14}) {
    for (int i = 0; i < 30000; ++i) {
      const Vec3d a{u(rng), u(rng), u(rng)};
      const Vec3d d = random_unit(rng);
      Vec3d side = cross(d, random_unit(rng));
      side = (1 / norm(side)) * side;
      const Vec3d b = a + 2.0 * d;
      const Vec3d c = i % 3 == 0   ? a + 1.5 * d + thin * 1.5 * side
                      : i % 3 == 1 ? a + -1.0 * d + thin * side
                                   : b + thin * side;
      const Vec3d p = a + 3.0 * Vec3d{u(rng), u(rng), u(rng)};
      const double got = dist(p, closest_point_on_triangle(p, a, b, c));
      ASSERT_NEAR(got, double(reference_distance(p, a, b, c, false)), 2e-8) << thin << " " << i;
    }
  }
}

// ---- point to mesh ---------------------------------------------------------------------------

TEST(MeshDistance, EqualsBruteForceInsideOutsideAndFarFromASphere) {
  const TriMesh mesh = sphere(8, 0.5, {1, -2, 3});
  ASSERT_TRUE(measure_mesh(mesh).closed());
  ASSERT_GT(mesh.triangle_count(), 5000u);
  const MeshDistance md(mesh);
  EXPECT_EQ(md.triangle_count(), mesh.triangle_count());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (double lo_r : {0.0, 7.0, 8.5, 20.0, 1e4}) {
    for (int i = 0; i < 300; ++i) {
      const double radius = lo_r + (lo_r == 0 ? 7.5 : lo_r) * u(rng);
      const Vec3d p = Vec3d{1, -2, 3} + radius * random_unit(rng);
      const double brute = brute_force_distance(mesh, p);
      ASSERT_NEAR(md.distance(p), brute, 1e-12 * (1 + brute)) << "radius " << radius;
      const Vec3d q = md.closest_point(p);
      ASSERT_NEAR(dist(p, q), brute, 1e-12 * (1 + brute));
      ASSERT_LT(md.distance(q), 1e-9);  // the closest point is on the mesh
    }
  }
}

TEST(MeshDistance, EqualsBruteForceOnATiltedTorusFarFromTheOrigin) {
  // CT-like world coordinates (hundreds of mm) and a surface whose normals take every direction:
  // the oriented boxes' float axes and bounds must stay conservative there.
  const Vec3d centre{210.5, -148.25, 402};
  const double big = 9, small = 3;
  Volume<float> field;
  const double spacing = 0.35;
  const auto n = static_cast<int64_t>(2 * (big + small + 2) / spacing) + 1;
  field.grid.dims = {n, n, n};
  field.grid.spacing = {spacing, spacing, spacing};
  const double half = spacing * double(n - 1) / 2;
  field.grid.origin = {centre.x - half, centre.y - half, centre.z - half};
  field.voxels.resize(field.grid.voxel_count());
  const double c = std::cos(0.7), s = std::sin(0.7);
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i) {
        const Vec3d w = field.grid.to_world({double(i), double(j), double(k)}) - centre;
        const Vec3d p{w.x, c * w.y - s * w.z, s * w.y + c * w.z};  // tilted about x
        field.at(i, j, k) = static_cast<float>(small - std::hypot(std::hypot(p.x, p.y) - big, p.z));
      }
  const TriMesh mesh = marching_cubes(field, {.iso = 0});
  ASSERT_EQ(measure_mesh(mesh).euler, 0);
  const MeshDistance md(mesh);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  for (double reach : {4.0, 15.0, 300.0}) {
    for (int i = 0; i < 300; ++i) {
      const Vec3d p = centre + reach * Vec3d{u(rng), u(rng), u(rng)};
      const double brute = brute_force_distance(mesh, p);
      ASSERT_NEAR(md.distance(p), brute, 1e-12 * (1 + brute)) << "reach " << reach;
    }
  }
}

TEST(MeshDistance, VerticesOfAMeshAreAtDistanceZero) {
  const TriMesh mesh = sphere(6, 0.4);
  const MeshDistance md(mesh);
  for (const Vec3f& v : mesh.positions) {
    ASSERT_EQ(md.distance(to_double(v)), 0.0);
    ASSERT_EQ(dist(md.closest_point(to_double(v)), to_double(v)), 0.0);
  }
}

TEST(MeshDistance, HandlesTinyMeshesDegenerateTrianglesAndEmptyMeshes) {
  const MeshDistance none(TriMesh{});
  EXPECT_EQ(none.distance({1, 2, 3}), kInf);
  EXPECT_EQ(none.closest_point({1, 2, 3}).x, kInf);
  EXPECT_EQ(none.triangle_count(), 0u);

  TriMesh one;
  one.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  one.indices = {0, 1, 2};
  EXPECT_NEAR(MeshDistance(one).distance({0.2, 0.2, 5}), 5, 1e-15);

  // A mesh of only degenerate triangles: a segment and a point.
  TriMesh flat;
  flat.positions = {{0, 0, 0}, {2, 0, 0}, {4, 0, 0}, {7, 7, 7}};
  flat.indices = {0, 1, 2, 3, 3, 3};
  const MeshDistance md(flat);
  EXPECT_NEAR(md.distance({1, 3, 4}), 5, 1e-15);
  EXPECT_NEAR(md.distance({7, 7, 9}), 2, 1e-15);
  EXPECT_NEAR(md.distance({-3, 0, 4}), 5, 1e-15);

  // Every tree depth from a root leaf upwards against brute force.
  std::mt19937 rng(6);
  std::uniform_real_distribution<float> u(-5, 5);
  for (int n : {1, 2, 3, 4, 5, 8, 9, 17, 33, 100, 1000}) {
    TriMesh m;
    for (int t = 0; t < 3 * n; ++t) {
      m.positions.push_back({u(rng), u(rng), u(rng)});
      m.indices.push_back(static_cast<uint32_t>(t));
    }
    const MeshDistance index(m);
    for (int i = 0; i < 100; ++i) {
      const Vec3d p{3 * u(rng), 3 * u(rng), 3 * u(rng)};
      ASSERT_NEAR(index.distance(p), brute_force_distance(m, p), 1e-12) << n;
    }
  }
}

// ---- mesh to mesh ----------------------------------------------------------------------------

TEST(Deviation, OfAMeshFromItselfIsZero) {
  const TriMesh mesh = sphere(6, 0.4, {100, 200, -50});
  const Deviation d = mesh_deviation(mesh, mesh);
  // Vertices are exactly on the mesh; centroids are off their own triangle's plane by rounding.
  EXPECT_LE(d.hausdorff, 1e-12);
  EXPECT_LE(d.mean, 1e-12);
  EXPECT_LE(d.p95, 1e-12);
  EXPECT_GE(d.mean, 0);
}

TEST(Deviation, CubeShiftedAlongAFaceNormal) {
  const TriMesh a = cube(10);
  const TriMesh b = cube(10, {0, 0, 0.3f});
  ASSERT_TRUE(measure_mesh(a).closed());
  ASSERT_NEAR(measure_mesh(a).volume_mm3, 1000, 1e-9);
  const Deviation ab = mesh_deviation(a, b);
  EXPECT_NEAR(ab.hausdorff, 0.3, 1e-6);
  // Per direction, 8 of the 20 samples (4 vertices, 4 centroids of the top and bottom faces) are
  // 0.3 away; the others lie on the other cube's side faces. 16 of 40 overall.
  EXPECT_NEAR(ab.mean, 16 * 0.3 / 40, 1e-6);
  EXPECT_NEAR(ab.p95, 0.3, 1e-6);
  const Deviation ba = mesh_deviation(b, a);
  EXPECT_EQ(ab.hausdorff, ba.hausdorff);
  EXPECT_EQ(ab.mean, ba.mean);
  EXPECT_EQ(ab.p95, ba.p95);
  // A vertex no triangle uses is not on the surface and is not sampled.
  TriMesh with_unused = a;
  with_unused.positions.push_back({50, 50, 50});
  const Deviation unused = mesh_deviation(with_unused, b);
  EXPECT_EQ(unused.hausdorff, ab.hausdorff);
  EXPECT_EQ(unused.mean, ab.mean);
}

TEST(Deviation, MatchesBruteForceAndIsSymmetricAndThreadCountIndependent) {
  const TriMesh a = sphere(5, 0.5);
  const TriMesh b = sphere(5.5, 0.45, {0.7, 0.2, -0.4});
  // Brute force: every sample of each mesh against every triangle of the other.
  const Deviation brute = every_sample_deviation(a, b, brute_force_distance);

  Deviation one, two, four, reverse;
  tbb::task_arena(1).execute([&] { one = mesh_deviation(a, b); });
  tbb::task_arena(2).execute([&] { two = mesh_deviation(a, b); });
  tbb::task_arena(4).execute([&] { four = mesh_deviation(a, b); });
  reverse = mesh_deviation(b, a);
  EXPECT_NEAR(one.hausdorff, brute.hausdorff, 1e-12);
  EXPECT_NEAR(one.mean, brute.mean, 1e-12);
  EXPECT_NEAR(one.p95, brute.p95, 1e-12);
  EXPECT_GT(one.hausdorff, 0.5);  // the shapes really differ
  for (const Deviation& other : {two, four, reverse}) {
    EXPECT_EQ(one.hausdorff, other.hausdorff);
    EXPECT_EQ(one.mean, other.mean);
    EXPECT_EQ(one.p95, other.p95);
  }
}

// Above 2 x 2^16 samples the mean and the 95th percentile come from a stratified subset and the
// Hausdorff distance from a pruned pass over the rest: the Hausdorff distance must stay exact,
// the statistics within 1 % of every sample's.
TEST(Deviation, LargeMeshesKeepTheExactHausdorffAndStatisticsWithinOnePercent) {
  const TriMesh a = sphere(14, 0.18);
  const TriMesh b = sphere(14.5, 0.7, {0.6, -0.3, 0.2});
  // the stratified path, two or more samples a stratum
  ASSERT_GT(a.positions.size() + a.triangle_count() + b.positions.size() + b.triangle_count(),
            size_t{3} << 16);
  const MeshDistance to_a(a), to_b(b);
  const Deviation every = every_sample_deviation(
      a, b, [&](const TriMesh& to, Vec3d p) { return (&to == &a ? to_a : to_b).distance(p); });

  Deviation one, two;
  tbb::task_arena(1).execute([&] { one = mesh_deviation(a, b); });
  tbb::task_arena(2).execute([&] { two = mesh_deviation(a, b); });
  const Deviation reverse = mesh_deviation(b, a);
  EXPECT_NEAR(one.hausdorff, every.hausdorff, 1e-12);
  EXPECT_GT(one.hausdorff, 0.5);  // the shapes really differ
  EXPECT_NEAR(one.mean, every.mean, 0.01 * every.mean);
  EXPECT_NEAR(one.p95, every.p95, 0.01 * every.p95);
  for (const Deviation& other : {two, reverse}) {
    EXPECT_EQ(one.hausdorff, other.hausdorff);
    EXPECT_EQ(one.mean, other.mean);
    EXPECT_EQ(one.p95, other.p95);
  }
}

// A mesh and its smoothed copy share their triangles, which bounds each search by the
// counterpart's distance; the answer must be the unbounded one. Rotating each triangle's corners
// keeps the surface (and the samples) but hides the shared triangles.
TEST(Deviation, SharedTrianglesGiveTheSameAnswerAsAnUnboundedSearch) {
  const TriMesh a = sphere(6, 0.4, {10, -20, 30});
  TriMesh b = a;
  smooth_mesh(b, {.method = SmoothMethod::laplacian, .iterations = 3, .preserve_volume = false});
  TriMesh b_rotated = b;
  for (size_t t = 0; t < b.triangle_count(); ++t)
    std::rotate(b_rotated.indices.begin() + 3 * t, b_rotated.indices.begin() + 3 * t + 1,
                b_rotated.indices.begin() + 3 * t + 3);
  const Deviation bounded = mesh_deviation(a, b);
  const Deviation unbounded = mesh_deviation(a, b_rotated);
  EXPECT_GT(bounded.hausdorff, 0.01);  // the smoothing did move the surface
  EXPECT_NEAR(bounded.hausdorff, unbounded.hausdorff, 1e-12);
  EXPECT_NEAR(bounded.mean, unbounded.mean, 1e-12);
  EXPECT_NEAR(bounded.p95, unbounded.p95, 1e-12);
}

TEST(Deviation, EmptyMeshes) {
  const TriMesh empty;
  const TriMesh c = cube(1);
  const Deviation none = mesh_deviation(empty, empty);
  EXPECT_EQ(none.hausdorff, 0);
  EXPECT_EQ(none.mean, 0);
  EXPECT_EQ(none.p95, 0);
  for (const Deviation& d : {mesh_deviation(c, empty), mesh_deviation(empty, c)}) {
    EXPECT_EQ(d.hausdorff, kInf);
    EXPECT_EQ(d.mean, kInf);
    EXPECT_EQ(d.p95, kInf);
  }
}

}  // namespace
}  // namespace segmesh
