// Mesh smoothing: each method's update rule on meshes whose answer is known in closed form (the
// regular octahedron, whose coordinates are eigenvectors of the umbrella operator), the windowed
// sinc filter against numbers from VTK 9.1's vtkWindowedSincPolyDataFilter, what every method does
// to the volume and the shape of a voxelised sphere, and the guarantees: connectivity untouched,
// unit outward normals, identical output for any thread count, odd input handled.
#include "segmesh/smoothing.hpp"
#include "segmesh/detail/triangle_scatter.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"

namespace segmesh {
namespace {

constexpr SmoothMethod kMethods[] = {SmoothMethod::laplacian, SmoothMethod::hc,
                                     SmoothMethod::taubin, SmoothMethod::sinc};

// The regular octahedron with circumradius 1 around `c`, wound counter-clockwise from outside.
// Each vertex's four neighbours average to c, so p - c is an eigenvector of the umbrella operator
// K = I - avg with eigenvalue 1: every linear filter g(K) scales the octahedron by g(1) about c.
TriMesh octahedron(Vec3d c = {}) {
  TriMesh m;
  const Vec3d p[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (const Vec3d& q : p) m.positions.push_back(to_float(c + q));
  m.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  return m;
}

// Largest deviation of `mesh` from the octahedron around c scaled by s.
double octahedron_error(const TriMesh& mesh, Vec3d c, double s) {
  const TriMesh unit = octahedron();
  double worst = 0;
  for (size_t i = 0; i < 6; ++i) {
    const Vec3d expected = c + s * to_double(unit.positions[i]);
    worst = std::max(worst, norm(to_double(mesh.positions[i]) - expected));
  }
  return worst;
}

TEST(SmoothMethodNames, RoundTripAndDefaults) {
  for (SmoothMethod m : {SmoothMethod::none, SmoothMethod::laplacian, SmoothMethod::hc,
                         SmoothMethod::taubin, SmoothMethod::sinc})
    EXPECT_EQ(parse_smooth_method(smooth_method_name(m)), m);
  EXPECT_EQ(smooth_method_name(SmoothMethod::hc), "hc");
  EXPECT_FALSE(parse_smooth_method("HC").has_value());
  EXPECT_FALSE(parse_smooth_method("gauss").has_value());
  EXPECT_EQ(default_smooth_iterations(SmoothMethod::laplacian), 2);
  EXPECT_EQ(default_smooth_iterations(SmoothMethod::hc), 2);
  EXPECT_EQ(default_smooth_iterations(SmoothMethod::taubin), 20);
  EXPECT_EQ(default_smooth_iterations(SmoothMethod::sinc), 20);
}

TEST(SmoothOctahedron, LaplacianScalesByOneMinusLambdaPerStep) {
  const Vec3d c{250.5, -130.25, 480};
  TriMesh m = octahedron(c);
  smooth_mesh(m, {.method = SmoothMethod::laplacian, .iterations = 3, .lambda = 0.5, .preserve_volume = false});
  EXPECT_LT(octahedron_error(m, c, 0.125), 1e-4);
  m = octahedron(c);
  smooth_mesh(m, {.method = SmoothMethod::laplacian, .preserve_volume = false});  // lambda 1: all at the neighbours' average
  EXPECT_LT(octahedron_error(m, c, 0.0), 1e-4);
}

TEST(SmoothOctahedron, TaubinScalesByLambdaMuProductPerIteration) {
  const Vec3d c{-90, 310, 12.5};
  TriMesh m = octahedron(c);
  const SmoothOptions o{.method = SmoothMethod::taubin, .iterations = 3, .preserve_volume = false};
  smooth_mesh(m, o);
  // One iteration = one lambda and one mu step: (1 - lambda)(1 - mu) per iteration.
  EXPECT_LT(octahedron_error(m, c, std::pow((1 - o.taubin_lambda) * (1 - o.taubin_mu), 3)), 1e-5);
}

TEST(SmoothOctahedron, HcFollowsVollmerMenclMueller) {
  // q = p; p = avg(q_j) = c; b_i = p_i - (alpha o_i + (1 - alpha) q_i); the neighbours' b_j
  // average to 0 (opposite pairs), so p_i = c - beta b_i. Relative to c, with o the unit
  // octahedron: alpha 0 halves the shape each iteration (0.25 after two), alpha 1 stays at beta
  // (0.5). The thesis' Algorithm 1 as printed (b_i instead of b_j in the sum) would return the
  // octahedron unchanged.
  const Vec3d c{17, -420, 333};
  TriMesh m = octahedron(c);
  smooth_mesh(m, {.method = SmoothMethod::hc, .iterations = 2, .alpha = 0.0, .beta = 0.5, .preserve_volume = false});
  EXPECT_LT(octahedron_error(m, c, 0.25), 1e-4);
  // The third iteration recomputes the umbrella of the original positions that the second one
  // reuses from the first (smoothing.cpp): the same rule, 0.125 after three.
  m = octahedron(c);
  smooth_mesh(m, {.method = SmoothMethod::hc, .iterations = 3, .alpha = 0.0, .beta = 0.5, .preserve_volume = false});
  EXPECT_LT(octahedron_error(m, c, 0.125), 1e-4);
  m = octahedron(c);
  smooth_mesh(m, {.method = SmoothMethod::hc, .iterations = 2, .alpha = 1.0, .beta = 0.5, .preserve_volume = false});
  EXPECT_LT(octahedron_error(m, c, 0.5), 1e-4);
  m = octahedron(c);
  smooth_mesh(m, {.method = SmoothMethod::hc, .iterations = 1, .alpha = 0.0, .beta = 0.2, .preserve_volume = false});
  EXPECT_LT(octahedron_error(m, c, 0.2), 1e-4);
}

// f(k) = sum_n c_n cos(n acos(1 - k/2)).
double sinc_response(const std::vector<double>& c, double k) {
  double f = 0;
  for (size_t n = 0; n < c.size(); ++n) f += c[n] * std::cos(double(n) * std::acos(1 - k / 2));
  return f;
}

// x of vertex (1, 0, 0) of the octahedron around the origin after VTK 9.1's
// vtkWindowedSincPolyDataFilter (double points; boundary and feature-edge smoothing off,
// non-manifold smoothing on, NormalizeCoordinates on): the filter's response at k = 1.
struct VtkSinc {
  int iterations;
  double pass_band, response_at_1;
};
constexpr VtkSinc kVtk91[] = {{20, 0.01, 0.0007882327532843367},   {20, 0.1, -0.000894282599885873},
                              {40, 0.001, -0.0002503957308264281}, {20, 1.0, 0.9991196337450461},
                              {10, 0.5, 0.770936542437354},        {20, 1.99, 1.0017107521407715}};

TEST(SmoothSinc, CoefficientsMatchVtkAndPassTheirPassBand) {
  for (const VtkSinc& v : kVtk91) {
    const std::vector<double> c = windowed_sinc_coefficients(v.iterations, v.pass_band);
    ASSERT_EQ(c.size(), size_t(v.iterations + 1));
    EXPECT_NEAR(sinc_response(c, 1.0), v.response_at_1, 1e-12)
        << v.iterations << " " << v.pass_band;
    EXPECT_NEAR(sinc_response(c, v.pass_band), 1.0, 1e-3) << v.iterations << " " << v.pass_band;
  }
  // The Hamming window's gain at k = 0 is not 1 (header comment): 3D Slicer's default scales
  // meshes by 1.0012 about their box centre.
  EXPECT_NEAR(sinc_response(windowed_sinc_coefficients(20, 0.01), 0.0), 1.00123, 1e-5);
  // A low pass: the staircase frequencies near k = 2 are damped.
  EXPECT_LT(std::abs(sinc_response(windowed_sinc_coefficients(20, 0.01), 1.5)), 0.01);
  EXPECT_EQ(windowed_sinc_coefficients(1, 0.1).size(), 2u);
  EXPECT_THROW(windowed_sinc_coefficients(0, 0.1), std::invalid_argument);
  EXPECT_THROW(windowed_sinc_coefficients(20, 0.0), std::invalid_argument);
}

TEST(SmoothSinc, OctahedronIsScaledByTheResponseAtOneAboutItsBoxCentre) {
  const Vec3d c{-310.5, 95.25, 450};
  for (const VtkSinc& v : kVtk91) {
    TriMesh m = octahedron(c);
    smooth_mesh(
        m, {.method = SmoothMethod::sinc, .iterations = v.iterations, .pass_band = v.pass_band,
            .sinc_unit_gain = false, .preserve_volume = false});
    EXPECT_LT(octahedron_error(m, c, v.response_at_1), 1e-4) << v.iterations << " " << v.pass_band;
  }
}

// ---------------------------------------------------------------------------------------------
// A voxelised ball: radius 4.5 mm on a 0.25 x 0.3 x 0.45 mm grid (18, 15 and 10 voxels), centre
// ~600 mm from the world origin at a generic offset in its voxel, two voxels of background around.

struct Ball {
  Vec3d centre{-230.3, 180.7, 510.1};
  double radius = 4.5;
};

TriMesh voxelised_ball(const Ball& b) {
  Volume<uint8_t> v;
  v.grid.spacing = {0.25, 0.3, 0.45};
  const double c[3] = {b.centre.x, b.centre.y, b.centre.z};
  for (int a = 0; a < 3; ++a) {
    const double half = b.radius + 2 * v.grid.spacing[a];
    v.grid.origin[a] = std::floor(c[a] - half);
    v.grid.dims[a] =
        static_cast<int64_t>(std::ceil((c[a] + half - v.grid.origin[a]) / v.grid.spacing[a])) + 1;
  }
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 0; k < v.grid.dims[2]; ++k)
    for (int64_t j = 0; j < v.grid.dims[1]; ++j)
      for (int64_t i = 0; i < v.grid.dims[0]; ++i)
        v.at(i, j, k) =
            norm(v.grid.to_world({double(i), double(j), double(k)}) - b.centre) <= b.radius;
  return marching_cubes(v, McOptions{});
}

double rms_distance(const TriMesh& m, const Ball& b) {
  double sum2 = 0;
  for (const Vec3f& p : m.positions) {
    const double d = norm(to_double(p) - b.centre) - b.radius;
    sum2 += d * d;
  }
  return std::sqrt(sum2 / double(m.positions.size()));
}

// RMS length of the umbrella vectors avg(neighbours) - p: large on a staircase, small on a
// smooth surface (on a sphere of edge length h about h^2 / (2 R)).
double roughness(const TriMesh& m) {
  std::vector<Vec3d> sum(m.positions.size());
  std::vector<std::vector<uint32_t>> nb(m.positions.size());
  for (size_t t = 0; t < m.triangle_count(); ++t)
    for (int c = 0; c < 3; ++c) {
      nb[m.indices[3 * t + c]].push_back(m.indices[3 * t + (c + 1) % 3]);
      nb[m.indices[3 * t + c]].push_back(m.indices[3 * t + (c + 2) % 3]);
    }
  double total = 0;
  for (size_t i = 0; i < nb.size(); ++i) {
    std::sort(nb[i].begin(), nb[i].end());
    nb[i].erase(std::unique(nb[i].begin(), nb[i].end()), nb[i].end());
    Vec3d avg{};
    for (uint32_t j : nb[i]) avg = avg + to_double(m.positions[j]);
    const Vec3d u = (1.0 / double(nb[i].size())) * avg - to_double(m.positions[i]);
    total += dot(u, u);
  }
  return std::sqrt(total / double(nb.size()));
}

class SmoothSphere : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { mesh_ = new TriMesh(voxelised_ball(Ball{})); }
  static void TearDownTestSuite() { delete mesh_; }
  // The plain filters (volume restoration off): what they do to a sphere on their own.
  static TriMesh smoothed(SmoothOptions o) {
    TriMesh m = *mesh_;
    o.preserve_volume = false;
    smooth_mesh(m, o);
    return m;
  }
  static double volume_change(const TriMesh& m) {
    return measure_mesh(m).volume_mm3 / measure_mesh(*mesh_).volume_mm3 - 1;
  }
  static TriMesh* mesh_;
};
TriMesh* SmoothSphere::mesh_ = nullptr;

TEST_F(SmoothSphere, VolumeAndDistanceToTheTrueSphere) {
  // Measured (volume against the unsmoothed mesh; RMS distance of the vertices to the true sphere,
  // 0.075 mm unsmoothed): Laplacian -1.34 %, 0.034 mm; HC -0.012 %, 0.048 mm; Taubin +0.35 %,
  // 0.034 mm (its gain exceeds 1 a little below k_pb, and a sphere's shape lies there); sinc
  // +0.55 %, 0.021 mm (the Hamming-windowed series has f(0) = sum c_n > 1 here: a slight growth).
  const Ball ball;
  ASSERT_TRUE(measure_mesh(*mesh_).closed());
  const double rms_before = rms_distance(*mesh_, ball);
  EXPECT_NEAR(rms_before, 0.075, 0.01);  // the staircase: a sixth of the 0.45 mm z-spacing
  std::array<double, 5> change{}, rms{};
  for (SmoothMethod method : kMethods) {
    const TriMesh m = smoothed({.method = method, .preserve_volume = false});
    change[static_cast<int>(method)] = volume_change(m);
    rms[static_cast<int>(method)] = rms_distance(m, ball);
  }
  const auto at = [](const std::array<double, 5>& a, SmoothMethod m) {
    return a[static_cast<int>(m)];
  };
  // Laplacian (lambda 1, 2 iterations) shrinks, and the most; the others far less.
  EXPECT_LT(at(change, SmoothMethod::laplacian), -0.01);
  EXPECT_GT(at(change, SmoothMethod::laplacian), -0.02);
  for (SmoothMethod m : {SmoothMethod::hc, SmoothMethod::taubin, SmoothMethod::sinc})
    EXPECT_LT(std::abs(at(change, m)), 0.5 * std::abs(at(change, SmoothMethod::laplacian)))
        << smooth_method_name(m);
  EXPECT_LT(std::abs(at(change, SmoothMethod::hc)), 0.0005);
  EXPECT_LT(std::abs(at(change, SmoothMethod::taubin)), 0.005);
  EXPECT_LT(std::abs(at(change, SmoothMethod::sinc)), 0.008);
  // Every method brings the vertices closer to the true sphere; the windowed sinc the closest.
  for (SmoothMethod m : kMethods) EXPECT_LT(at(rms, m), 0.7 * rms_before) << smooth_method_name(m);
  for (SmoothMethod m : {SmoothMethod::laplacian, SmoothMethod::hc, SmoothMethod::taubin})
    EXPECT_LT(at(rms, SmoothMethod::sinc), at(rms, m)) << smooth_method_name(m);
}

TEST_F(SmoothSphere, KeepsConnectivityAndClosednessAndGivesUnitOutwardNormals) {
  const Ball ball;
  for (SmoothMethod method : kMethods) {
    const TriMesh m = smoothed({.method = method, .preserve_volume = false});
    const auto name = smooth_method_name(method);
    EXPECT_EQ(m.positions.size(), mesh_->positions.size()) << name;
    EXPECT_EQ(m.indices, mesh_->indices) << name;
    const MeshMeasures measures = measure_mesh(m);
    EXPECT_TRUE(measures.closed()) << name;
    EXPECT_EQ(measures.degenerate_triangles, 0) << name;
    EXPECT_EQ(measures.euler, 2) << name;
    ASSERT_EQ(m.normals.size(), m.positions.size()) << name;
    double worst_length = 0, worst_cos = 1;
    for (size_t i = 0; i < m.positions.size(); ++i) {
      const Vec3d n = to_double(m.normals[i]);
      const Vec3d radial = to_double(m.positions[i]) - ball.centre;
      worst_length = std::max(worst_length, std::abs(norm(n) - 1));
      worst_cos = std::min(worst_cos, dot(n, radial) / norm(radial));
    }
    EXPECT_LT(worst_length, 1e-6) << name;
    EXPECT_GT(worst_cos, 0.5) << name;  // outwards, within 60 degrees of the radius everywhere
  }
}

TEST_F(SmoothSphere, SameResultForOneAndFourThreads) {
  // A larger ball (27 k vertices, a dozen blocks of work) and about 20 sweeps per method, so
  // that a race (say, a sweep reading positions another thread is updating) would show.
  const TriMesh big = voxelised_ball({.radius = 12});
  // Enough triangles for chunks of the scatter that run side by side (triangle_scatter.hpp).
  ASSERT_GE(triangle_chunks(big.indices).count(), 3u);
  for (SmoothMethod method : kMethods) {
    const SmoothOptions o{
        .method = method,
        .iterations = method == SmoothMethod::hc || method == SmoothMethod::taubin ? 10 : 20};
    TriMesh one = big, four = big;
    tbb::task_arena(1).execute([&] { smooth_mesh(one, o); });
    tbb::task_arena(4).execute([&] { smooth_mesh(four, o); });
    const auto name = smooth_method_name(method);
    ASSERT_EQ(one.positions.size(), four.positions.size());
    EXPECT_EQ(0, std::memcmp(one.positions.data(), four.positions.data(),
                             one.positions.size() * sizeof(Vec3f)))
        << name;
    ASSERT_EQ(one.normals.size(), four.normals.size());
    EXPECT_EQ(
        0, std::memcmp(one.normals.data(), four.normals.data(), one.normals.size() * sizeof(Vec3f)))
        << name;
  }
}

TEST_F(SmoothSphere, SincNearPassBandTwoHardlyMovesAndSmoothsMoreWithLowerBandOrMoreIterations) {
  const auto moved = [](const TriMesh& m) {
    double worst = 0;
    for (size_t i = 0; i < m.positions.size(); ++i)
      worst = std::max(worst, norm(to_double(m.positions[i]) - to_double(mesh_->positions[i])));
    return worst;
  };
  // Pass band 1.99 passes nearly everything: measured 0.004 mm at most (the default moves
  // vertices by up to 0.27 mm) and the same roughness.
  const double rough_before = roughness(*mesh_);
  const TriMesh open = smoothed({.method = SmoothMethod::sinc, .pass_band = 1.99, .preserve_volume = false});
  EXPECT_LT(moved(open), 0.01);
  EXPECT_NEAR(roughness(open), rough_before, 0.01 * rough_before);
  EXPECT_GT(moved(smoothed({.method = SmoothMethod::sinc, .preserve_volume = false})), 0.2);
  // Roughness falls with the pass band at a fixed iteration count and with the iteration count at
  // a fixed pass band (measured 0.099 unsmoothed; 0.0841, 0.0154, 0.0122, 0.0113 at 20 iterations).
  const double bands[] = {1.0, 0.1, 0.01, 0.001};
  const int counts[] = {10, 20, 40};
  double r[4][3];
  for (int b = 0; b < 4; ++b)
    for (int c = 0; c < 3; ++c)
      r[b][c] = roughness(
          smoothed({.method = SmoothMethod::sinc, .iterations = counts[c], .pass_band = bands[b], .preserve_volume = false}));
  for (int b = 0; b < 4; ++b)
    for (int c = 0; c < 3; ++c) {
      if (b > 0) {
        EXPECT_LT(r[b][c], r[b - 1][c]) << bands[b] << " " << counts[c];
      }
      if (c > 0) {
        EXPECT_LT(r[b][c], r[b][c - 1]) << bands[b] << " " << counts[c];
      }
    }
  EXPECT_LT(r[0][0], rough_before);
}

TEST(SmoothEdgeCases, EmptyMeshIsolatedVertexAndNoTriangles) {
  TriMesh empty;
  for (SmoothMethod method : kMethods) {
    smooth_mesh(empty, {.method = method, .preserve_volume = false});
    EXPECT_TRUE(empty.positions.empty());
    EXPECT_TRUE(empty.normals.empty());
  }
  for (SmoothMethod method : kMethods) {
    TriMesh m = octahedron({100, 200, 300});
    const Vec3f lonely{-512.25f, 7.5f, 1000.125f};
    m.positions.push_back(lonely);
    smooth_mesh(m, {.method = method, .preserve_volume = false});
    EXPECT_EQ(m.positions[6].x, lonely.x);
    EXPECT_EQ(m.positions[6].y, lonely.y);
    EXPECT_EQ(m.positions[6].z, lonely.z);
    ASSERT_EQ(m.normals.size(), 7u);
    EXPECT_EQ(m.normals[6].z, 1.0f);
    EXPECT_NE(m.positions[0].x, 101.0f) << smooth_method_name(method);  // the others did move
  }
  TriMesh points;
  points.positions = {{1, 2, 3}, {4, 5, 6}};
  smooth_mesh(points, {.method = SmoothMethod::sinc, .preserve_volume = false});
  EXPECT_EQ(points.positions[1].y, 5.0f);
  EXPECT_EQ(points.normals.size(), 2u);
}

TEST(SmoothEdgeCases, NonManifoldAndDegenerateInputIsSmoothedWithoutHarm) {
  // Three triangles on one edge (0, 1), a triangle repeating a vertex, a vertex shared by two
  // otherwise separate fans.
  TriMesh m;
  m.positions = {{0, 0, 0},    {1, 0, 0}, {0.5f, 1, 0},  {0.5f, -1, 0},
                 {0.5f, 0, 1}, {2, 1, 0}, {2, -1, 0.5f}, {3, 0, 0}};
  m.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4, 1, 1, 5, 1, 5, 6, 6, 5, 7};
  for (SmoothMethod method : kMethods) {
    TriMesh one = m, four = m;
    tbb::task_arena(1).execute([&] { smooth_mesh(one, {.method = method, .preserve_volume = false}); });
    tbb::task_arena(4).execute([&] { smooth_mesh(four, {.method = method, .preserve_volume = false}); });
    EXPECT_EQ(one.indices, m.indices);
    for (size_t i = 0; i < one.positions.size(); ++i) {
      EXPECT_TRUE(std::isfinite(one.positions[i].x) && std::isfinite(one.positions[i].y) &&
                  std::isfinite(one.positions[i].z));
      EXPECT_EQ(one.positions[i].x, four.positions[i].x);
      EXPECT_NEAR(norm(to_double(one.normals[i])), 1.0, 1e-6);
    }
  }
}

TEST(SmoothEdgeCases, NoneLeavesTheMeshAlone) {
  TriMesh m = octahedron({1, 2, 3});
  m.normals.assign(6, Vec3f{0, 1, 0});
  smooth_mesh(m, {});
  EXPECT_EQ(m.positions[0].x, 2.0f);
  EXPECT_EQ(m.normals[0].y, 1.0f);
}

TEST(SmoothEdgeCases, InvalidOptionsThrow) {
  TriMesh m = octahedron();
  EXPECT_THROW(smooth_mesh(m, {.method = SmoothMethod::laplacian, .iterations = -1, .preserve_volume = false}),
               std::invalid_argument);
  EXPECT_THROW(smooth_mesh(m, {.method = SmoothMethod::hc, .alpha = 1.5, .preserve_volume = false}), std::invalid_argument);
  EXPECT_THROW(smooth_mesh(m, {.method = SmoothMethod::hc, .beta = -0.1, .preserve_volume = false}), std::invalid_argument);
  EXPECT_THROW(smooth_mesh(m, {.method = SmoothMethod::sinc, .pass_band = 0, .preserve_volume = false}),
               std::invalid_argument);
  EXPECT_THROW(smooth_mesh(m, {.method = SmoothMethod::sinc, .pass_band = 2.5, .preserve_volume = false}),
               std::invalid_argument);
  EXPECT_THROW(smooth_mesh(m, {.method = SmoothMethod::laplacian, .lambda = NAN, .preserve_volume = false}),
               std::invalid_argument);
  EXPECT_EQ(m.positions[0].x, 1.0f);
}

TEST(SmoothEdgeCases, CancellingLeavesTheMeshUnchanged) {
  struct CancelAfter : Progress {
    mutable int checks = 0;
    bool cancelled() const override { return ++checks > 3; }
  };
  for (SmoothMethod method : kMethods) {
    TriMesh m = octahedron({5, 6, 7});
    CancelAfter progress;
    EXPECT_THROW(smooth_mesh(m, {.method = method, .iterations = 10, .preserve_volume = false}, progress), Cancelled);
    EXPECT_LT(octahedron_error(m, {5, 6, 7}, 1.0), 1e-6) << smooth_method_name(method);
  }
}

TEST(SmoothNormals, AreaWeightedUnitNormals) {
  // Octahedron: four congruent faces per vertex, so the normal points along the vertex.
  TriMesh m = octahedron({-40, 50, 600});
  compute_vertex_normals(m);
  const TriMesh unit = octahedron();
  for (size_t i = 0; i < 6; ++i)
    EXPECT_LT(norm(to_double(m.normals[i]) - to_double(unit.positions[i])), 1e-6);
  // Two triangles at a vertex, areas 1 and 3 (normals +z and +x): weighted 1 : 3.
  TriMesh w;
  w.positions = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, -3}, {0, 2, 0}};
  w.indices = {0, 1, 2, 0, 3, 4};
  compute_vertex_normals(w);
  const Vec3d expected = (1 / std::sqrt(10.0)) * Vec3d{3, 0, 1};
  EXPECT_LT(norm(to_double(w.normals[0]) - expected), 1e-6);
}

}  // namespace
}  // namespace segmesh

namespace segmesh {
namespace {

TEST_F(SmoothSphere, VolumeRestorationKeepsTheVolumeAndTheSmoothing) {
  const Ball ball;
  const double rms_before = rms_distance(*mesh_, ball);
  for (SmoothMethod method : kMethods) {
    TriMesh m = *mesh_;
    smooth_mesh(m, {.method = method});  // preserve_volume is on by default
    EXPECT_NEAR(volume_change(m), 0.0, 1e-4) << smooth_method_name(method);
    EXPECT_LT(rms_distance(m, ball), rms_before) << smooth_method_name(method);
    EXPECT_TRUE(measure_mesh(m).closed());
  }
}

TEST(SmoothVolume, ASpeckSmoothingWouldEraseKeepsItsShape) {
  // An octahedron collapses towards its centre under smoothing; with volume restoration on it
  // stays as it was rather than being blown up from almost nothing.
  TriMesh m = octahedron({10, 20, 30});
  const TriMesh before = m;
  smooth_mesh(m, {.method = SmoothMethod::laplacian, .iterations = 5});
  for (size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_FLOAT_EQ(m.positions[i].x, before.positions[i].x);
    EXPECT_FLOAT_EQ(m.positions[i].z, before.positions[i].z);
  }
}

}  // namespace
}  // namespace segmesh

#include "segmesh/pipeline.hpp"

namespace segmesh {
namespace {

TEST_F(SmoothSphere, TheDefaultBeats3DSlicersDefaultAndKeepsTheVolume) {
  // 3D Slicer's default (up to 5.6): VTK's windowed sinc, pass band 0.01, 20 iterations.
  const Ball ball;
  TriMesh slicer = *mesh_;
  smooth_mesh(slicer, {.method = SmoothMethod::sinc, .iterations = 20, .pass_band = 0.01,
                       .sinc_unit_gain = false, .preserve_volume = false});
  TriMesh ours = *mesh_;
  smooth_mesh(ours, default_smoothing());
  EXPECT_LT(rms_distance(ours, ball), rms_distance(slicer, ball));
  EXPECT_LT(std::abs(volume_change(ours)), 0.01);
  EXPECT_LT(std::abs(volume_change(ours)), std::abs(volume_change(slicer)));
  // Two HC iterations alone change the volume by less than 0.6 % (the reference lost 12.65 %).
  EXPECT_LT(std::abs(volume_change(smoothed({.method = SmoothMethod::hc, .iterations = 2}))), 0.006);
}

}  // namespace
}  // namespace segmesh
