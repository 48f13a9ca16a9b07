// The QEF of Dual Contouring (qef.hpp): the Jacobi eigen-decomposition against matrices with known
// eigen-pairs, solve_qef on plane configurations of known rank and minimiser (a corner, an edge, a
// face, a nearly parallel pair that the eps cut-off must drop), keep_in_box, and translated /
// merge / error against the samples accumulated or summed directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "segmesh/detail/qef.hpp"

namespace segmesh {
namespace {

Mat3d mul(const Mat3d& a, const Mat3d& b) {
  Mat3d c{};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
  return c;
}

Mat3d transpose(const Mat3d& m) {
  return {m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]};
}

Mat3d rotation(double ax, double ay, double az) {
  const Mat3d rx{1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax)};
  const Mat3d ry{std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay)};
  const Mat3d rz{std::cos(az), -std::sin(az), 0, std::sin(az), std::cos(az), 0, 0, 0, 1};
  return mul(rz, mul(ry, rx));
}

// R diag(d) R^T, symmetrised exactly (the product is symmetric only up to rounding).
Mat3d rotated_diagonal(const Mat3d& r, Vec3d d) {
  const Mat3d m = mul(r, mul(Mat3d{d.x, 0, 0, 0, d.y, 0, 0, 0, d.z}, transpose(r)));
  Mat3d s = m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) s[3 * i + j] = 0.5 * (m[3 * i + j] + m[3 * j + i]);
  return s;
}

Vec3d column(const Mat3d& m, int i) {
  return {m[i], m[3 + i], m[6 + i]};
}

Vec3d unit(Vec3d v) {
  return (1.0 / norm(v)) * v;
}

// Decomposes m, checks m v = lambda v for every pair and V^T V = I (to 1e-12), and returns the
// eigenvalues sorted ascending.
std::vector<double> checked_eigen(const Mat3d& m, const std::string& what) {
  Vec3d values;
  Mat3d vectors;
  symmetric_eigen(m, values, vectors);
  const double lambda[3] = {values.x, values.y, values.z};
  for (int i = 0; i < 3; ++i) {
    const Vec3d v = column(vectors, i);
    const Vec3d residual = m * v - lambda[i] * v;
    EXPECT_LT(norm(residual), 1e-12) << what << ": |A v - lambda v| for eigenvalue " << lambda[i];
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(dot(v, column(vectors, j)), i == j ? 1.0 : 0.0, 1e-12)
          << what << ": eigenvectors " << i << " and " << j << " not orthonormal";
    }
  }
  std::vector<double> sorted(lambda, lambda + 3);
  std::sort(sorted.begin(), sorted.end());
  return sorted;
}

void expect_values(const std::vector<double>& got, std::vector<double> expected,
                   const std::string& what) {
  std::sort(expected.begin(), expected.end());
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(got[i], expected[i], 1e-12) << what << ": eigenvalue " << i;
}

void expect_near(Vec3d a, Vec3d b, double tolerance, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tolerance) << what << " (x)";
  EXPECT_NEAR(a.y, b.y, tolerance) << what << " (y)";
  EXPECT_NEAR(a.z, b.z, tolerance) << what << " (z)";
}

TEST(SymmetricEigen, DiagonalMatrixKeepsItsValuesAndTheAxes) {
  const Mat3d m{3, 0, 0, 0, -1, 0, 0, 0, 7};
  Vec3d values;
  Mat3d vectors;
  symmetric_eigen(m, values, vectors);
  // Already diagonal: no rotation at all.
  EXPECT_EQ(values.x, 3);
  EXPECT_EQ(values.y, -1);
  EXPECT_EQ(values.z, 7);
  for (int i = 0; i < 9; ++i)
    EXPECT_EQ(vectors[i], identity3()[i]) << "diagonal: vectors[" << i << "]";
  expect_values(checked_eigen(m, "diagonal"), {3, -1, 7}, "diagonal");
}

TEST(SymmetricEigen, RotatedDiagonalGivesItsEigenvaluesAndRotatedAxes) {
  const Mat3d r = rotation(0.3, -1.1, 2.4);
  const Mat3d m = rotated_diagonal(r, {5, 2, 0.5});
  ASSERT_GT(std::abs(m[1]) + std::abs(m[2]) + std::abs(m[5]), 1.0) << "not far from diagonal";
  expect_values(checked_eigen(m, "rotated diag(5, 2, 0.5)"), {5, 2, 0.5},
                "rotated diag(5, 2, 0.5)");
  // Distinct eigenvalues: each eigenvector is the rotated axis, up to sign.
  Vec3d values;
  Mat3d vectors;
  symmetric_eigen(m, values, vectors);
  const double lambda[3] = {values.x, values.y, values.z};
  for (int i = 0; i < 3; ++i) {
    const int axis = std::abs(lambda[i] - 5) < 1e-9 ? 0 : std::abs(lambda[i] - 2) < 1e-9 ? 1 : 2;
    EXPECT_NEAR(std::abs(dot(column(vectors, i), column(r, axis))), 1.0, 1e-12)
        << "rotated diagonal: eigenvector of " << lambda[i];
  }
  // Negative and mixed-sign spectra, as well as a large scale.
  expect_values(
      checked_eigen(rotated_diagonal(rotation(1.0, 0.2, -0.7), {-4, 1, 3}), "mixed signs"),
      {-4, 1, 3}, "mixed signs");
}

TEST(SymmetricEigen, RepeatedEigenvalues) {
  const Mat3d r = rotation(-0.6, 0.9, 0.35);
  expect_values(checked_eigen(rotated_diagonal(r, {4, 4, 1}), "rotated diag(4, 4, 1)"), {4, 4, 1},
                "rotated diag(4, 4, 1)");
  expect_values(checked_eigen(rotated_diagonal(r, {0, 0, 2}), "rotated diag(0, 0, 2)"), {0, 0, 2},
                "rotated diag(0, 0, 2)");
  // The all-ones matrix: 3 once (along (1, 1, 1)), 0 twice.
  const Mat3d ones{1, 1, 1, 1, 1, 1, 1, 1, 1};
  expect_values(checked_eigen(ones, "all ones"), {0, 0, 3}, "all ones");
  // A multiple of the identity, and zero.
  expect_values(checked_eigen(Mat3d{2.5, 0, 0, 0, 2.5, 0, 0, 0, 2.5}, "2.5 I"), {2.5, 2.5, 2.5},
                "2.5 I");
  expect_values(checked_eigen(Mat3d{}, "zero"), {0, 0, 0}, "zero");
}

TEST(SymmetricEigen, RandomSymmetricMatricesKeepTraceAndDeterminant) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> value(-3, 3);
  for (int t = 0; t < 200; ++t) {
    Mat3d m;
    for (int i = 0; i < 3; ++i)
      for (int j = i; j < 3; ++j) m[3 * i + j] = m[3 * j + i] = value(rng);
    const std::string what = "random symmetric matrix " + std::to_string(t);
    const auto values = checked_eigen(m, what);
    EXPECT_NEAR(values[0] + values[1] + values[2], m[0] + m[4] + m[8], 1e-12) << what;
    EXPECT_NEAR(values[0] * values[1] * values[2], determinant(m), 1e-11) << what;
  }
}

// n . x = n . p for the samples (p_i, n_i) of planes.
struct Plane {
  Vec3d point;
  Vec3d normal;  // unit
};

// `per_plane` samples scattered over each plane, around `near`, none at `near` itself.
Qef sample_planes(const std::vector<Plane>& planes, Vec3d near, std::vector<int> per_plane,
                  unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-0.5, 0.5);
  Qef q;
  for (size_t k = 0; k < planes.size(); ++k) {
    const Plane& plane = planes[k];
    const Vec3d n = plane.normal;
    // Two directions in the plane.
    const Vec3d helper = std::abs(n.x) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0};
    const Vec3d u = unit(cross(n, helper)), w = cross(n, u);
    const Vec3d foot = near - dot(near - plane.point, n) * n;  // near projected onto the plane
    for (int s = 0; s < per_plane[k]; ++s) {
      q.add(foot + offset(rng) * u + offset(rng) * w, n);
    }
  }
  return q;
}

TEST(SolveQef, ThreeOrthogonalPlanesGiveTheirCornerWithRankThree) {
  const Vec3d corner{1.5, -2.0, 0.25};
  for (const Mat3d& r : {identity3(), rotation(0.4, -0.2, 1.3)}) {
    const std::string what = r == identity3() ? "axis-aligned corner" : "rotated corner";
    const std::vector<Plane> planes = {
        {corner, column(r, 0)}, {corner, column(r, 1)}, {corner, column(r, 2)}};
    const Qef q = sample_planes(planes, corner + Vec3d{0.3, 0.2, -0.1}, {3, 4, 5}, 1);
    ASSERT_EQ(q.count, 12);
    for (double eps : {0.5, 0.1, 1e-6}) {
      const QefSolution s = solve_qef(q, eps);
      EXPECT_EQ(s.rank, 3) << what << ", eps " << eps;
      expect_near(s.position, corner, 1e-12, what + ", eps " + std::to_string(eps));
      EXPECT_NEAR(s.error, 0, 1e-12) << what;
      EXPECT_NEAR(q.error(s.position), 0, 1e-12) << what;
    }
    // The corner is the minimum: any other point costs more.
    EXPECT_GT(q.error(corner + Vec3d{0.01, 0, 0}), 1e-6) << what;
  }
}

// A singular value on the cut-off, or within rounding of it, is kept; one clearly below is
// dropped. Four samples of the plane x = 1 and one of y = 2: singular values 2 and 1.
TEST(SolveQef, SingularValuesWithinRoundingOfTheCutOffAreKept) {
  Qef q;
  for (int i = 0; i < 4; ++i) q.add({1, double(i), 0}, {1, 0, 0});
  q.add({0, 2, 0}, {0, 1, 0});
  for (double eps : {0.5, 0.5 * (1 + 1e-12)}) {
    const QefSolution s = solve_qef(q, eps);
    EXPECT_EQ(s.rank, 2) << "eps " << eps;
    EXPECT_NEAR(s.position.y, 2, 1e-12) << "eps " << eps;
  }
  const QefSolution dropped = solve_qef(q, 0.5 * (1 + 1e-6));
  EXPECT_EQ(dropped.rank, 1);
  EXPECT_NEAR(dropped.position.y, q.mass_point().y, 1e-12);
}

TEST(SolveQef, TwoPlanesGiveThePointOfTheirLineClosestToTheMassPoint) {
  const Mat3d r = rotation(-0.5, 0.8, 0.15);
  const Vec3d on_line{0.7, 1.1, -0.4};
  const Vec3d n1 = column(r, 0), n2 = unit(column(r, 1) + 0.3 * column(r, 0));  // 73 degrees apart
  const Vec3d direction = unit(cross(n1, n2));
  // Samples around a point off the line: the mass point lies off the line too.
  const Vec3d near = on_line + 2.0 * direction + 0.8 * unit(n1 + n2);
  const Qef q = sample_planes({{on_line, n1}, {on_line, n2}}, near, {6, 5}, 2);
  const Vec3d mass = q.mass_point();
  const Vec3d expected = on_line + dot(mass - on_line, direction) * direction;
  ASSERT_GT(norm(mass - expected), 0.3) << "the mass point should lie off the line";
  for (double eps : {0.5, 0.1}) {
    const QefSolution s = solve_qef(q, eps);
    EXPECT_EQ(s.rank, 2) << "two planes, eps " << eps;
    expect_near(s.position, expected, 1e-12, "two planes, eps " + std::to_string(eps));
    EXPECT_NEAR(dot(s.position - mass, direction), 0, 1e-12) << "no slide along the line";
    EXPECT_NEAR(s.error, 0, 1e-12) << "two planes";
  }
}

TEST(SolveQef, OnePlaneGivesTheMassPointProjectedOntoIt) {
  const Vec3d n = unit({0.3, -0.8, 0.52});
  const Vec3d on_plane{-1, 2, 0.5};
  // Samples on the plane: the mass point lies on it and stays where it is.
  Qef q = sample_planes({{on_plane, n}}, on_plane + Vec3d{0.2, 0.1, 0.3}, {9}, 3);
  QefSolution s = solve_qef(q, 0.5);
  EXPECT_EQ(s.rank, 1) << "one plane";
  expect_near(s.position, q.mass_point(), 1e-12, "one plane: the mass point");
  EXPECT_NEAR(s.error, 0, 1e-12);
  // Samples without a normal (a vanished gradient) move the mass point off the plane; the solution
  // is the mass point projected onto the plane.
  q.add({4, 4, 4}, {0, 0, 0});
  q.add({3, -2, 1}, {0, 0, 0});
  const Vec3d mass = q.mass_point();
  ASSERT_GT(std::abs(dot(mass - on_plane, n)), 0.1) << "the mass point should lie off the plane";
  s = solve_qef(q, 0.5);
  EXPECT_EQ(s.rank, 1) << "one plane, mass point off it";
  expect_near(s.position, mass - dot(mass - on_plane, n) * n, 1e-12,
              "one plane: the mass point projected");
  EXPECT_NEAR(s.error, 0, 1e-12);
  // Two parallel planes, n . x = c and c + 0.4, equally sampled: the plane between them, at the
  // mass point, with the residual 0.2 at every sample.
  const Qef parallel = [&] {
    Qef a = sample_planes({{on_plane, n}}, on_plane, {5}, 4);
    a.merge(sample_planes({{on_plane + 0.4 * n, n}}, on_plane, {5}, 5));
    return a;
  }();
  s = solve_qef(parallel, 0.5);
  EXPECT_EQ(s.rank, 1) << "parallel planes";
  expect_near(s.position, parallel.mass_point(), 1e-12, "parallel planes: the mass point");
  EXPECT_NEAR(dot(s.position - on_plane, n), 0.2, 1e-12) << "parallel planes: halfway";
  EXPECT_NEAR(s.error, 10 * 0.2 * 0.2, 1e-12) << "parallel planes: residual";
}

TEST(SolveQef, EpsDropsTheSmallSingularValueOfNearlyParallelPlanes) {
  // z = 0 and a plane tilted by 0.01 rad about x, offset so the two meet 5 mm away at y = 5, plus
  // x = 0.3. Singular values about sqrt(6), sqrt(12) and 0.005 sqrt(12): the smallest is 0.005 of
  // the largest.
  const double delta = 0.01;
  const Vec3d n1{0, 0, 1}, n2{0, -std::sin(delta), std::cos(delta)}, n3{1, 0, 0};
  const Vec3d meet{0.3, 5.0, 0.0};  // on all three planes
  const Qef q = sample_planes({{meet, n1}, {meet, n2}, {meet, n3}}, {0.3, 0, 0}, {6, 6, 6}, 6);
  const Vec3d mass = q.mass_point();
  ASSERT_LT(norm(mass - Vec3d{0.3, 0, 0}), 0.3);
  // The dropped direction: the eigenvector of the smallest eigenvalue of n1 n1^T + n2 n2^T, the
  // difference of the two normals.
  const Vec3d dropped = unit(n1 - n2);
  for (double eps : {0.5, 0.01}) {
    const QefSolution s = solve_qef(q, eps);
    const std::string what = "nearly parallel planes, eps " + std::to_string(eps);
    EXPECT_EQ(s.rank, 2) << what;
    EXPECT_NEAR(s.position.x, 0.3, 1e-12) << what << ": on the plane x = 0.3";
    EXPECT_NEAR(dot(s.position - mass, dropped), 0, 1e-12)
        << what << ": moved along the dropped direction";
    EXPECT_LT(norm(s.position - mass), 0.5) << what << ": stays at the samples, not 5 mm away";
  }
  for (double eps : {1e-3, 1e-6}) {
    const QefSolution s = solve_qef(q, eps);
    const std::string what = "nearly parallel planes, eps " + std::to_string(eps);
    EXPECT_EQ(s.rank, 3) << what;
    expect_near(s.position, meet, 1e-9, what + ": the exact intersection");
    EXPECT_NEAR(s.error, 0, 1e-12) << what;
  }
}

TEST(SolveQef, EmptyQefGivesRankZeroAtTheOrigin) {
  const QefSolution s = solve_qef(Qef{}, 0.5);
  EXPECT_EQ(s.rank, 0);
  expect_near(s.position, {}, 0, "empty QEF");
  EXPECT_EQ(s.error, 0);
}

// True when p lies on the segment from a to b (to 1e-12).
bool on_segment(Vec3d p, Vec3d a, Vec3d b) {
  const Vec3d ab = b - a, ap = p - a;
  const double t = dot(ap, ab) / dot(ab, ab);
  return norm(cross(ab, ap)) <= 1e-12 * norm(ab) && t >= -1e-12 && t <= 1 + 1e-12;
}

// Inside [lo, hi] up to `slack` (the division t = (hi - m) / d may round a hair outside).
bool in_box(Vec3d p, Vec3d lo, Vec3d hi, double slack = 0) {
  return p.x >= lo.x - slack && p.y >= lo.y - slack && p.z >= lo.z - slack && p.x <= hi.x + slack &&
         p.y <= hi.y + slack && p.z <= hi.z + slack;
}

TEST(KeepInBox, PointOutsideMovesBackAlongTheLineTowardsTheMassPoint) {
  const Vec3d lo{0, 0, 0}, hi{1, 2, 1};
  const Vec3d mass{0.5, 0.5, 0.5};
  // Inside: unchanged.
  expect_near(keep_in_box({0.9, 1.9, 0.1}, mass, lo, hi), {0.9, 1.9, 0.1}, 1e-15, "inside");
  // Out through one face.
  expect_near(keep_in_box({3, 0.5, 0.5}, mass, lo, hi), {1, 0.5, 0.5}, 1e-15, "out in +x");
  // Out in two axes: the first face the segment from the mass point meets (x at t = 0.2, before
  // y at t = 0.6).
  expect_near(keep_in_box({3, 3, 0.5}, mass, lo, hi), {1, 1, 0.5}, 1e-15, "out in +x and +y");
  // Out below: z at t = 0.25 comes before y at t = 0.5.
  expect_near(keep_in_box({0.5, -0.5, -1.5}, mass, lo, hi), {0.5, 0.25, 0}, 1e-15,
              "out in -y and -z");
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> far(-5, 6);
  for (int t = 0; t < 500; ++t) {
    const Vec3d x{far(rng), far(rng), far(rng)};
    const Vec3d kept = keep_in_box(x, mass, lo, hi);
    const std::string what = "random point " + std::to_string(t);
    EXPECT_TRUE(in_box(kept, lo, hi, 1e-15))
        << what << ": " << kept.x << ", " << kept.y << ", " << kept.z;
    EXPECT_TRUE(on_segment(kept, mass, x)) << what << ": not on the line to the mass point";
    if (in_box(x, lo, hi)) {
      expect_near(kept, x, 1e-15, what + " (inside)");
    } else {  // as far towards x as the box allows: on the box's surface
      const double to_face = std::min({kept.x - lo.x, kept.y - lo.y, kept.z - lo.z, hi.x - kept.x,
                                       hi.y - kept.y, hi.z - kept.z});
      EXPECT_NEAR(to_face, 0, 1e-12) << what << ": stopped short of the box's surface";
    }
  }
  // A mass point outside the box is clamped into it first, then the line runs from there.
  const Vec3d outside_mass{1.5, 0.5, 0.5};
  expect_near(keep_in_box({-1, 0.5, 0.5}, outside_mass, lo, hi), {0, 0.5, 0.5}, 1e-15,
              "mass point outside");
  expect_near(keep_in_box({3, 3, 3}, Vec3d{5, 5, 5}, lo, hi), hi, 1e-15,
              "both outside, beyond the same corner");
}

struct Sample {
  Vec3d p, n;
};

std::vector<Sample> random_samples(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(-1, 1);
  std::vector<Sample> out;
  for (int i = 0; i < count; ++i) {
    const Vec3d p{coord(rng), coord(rng), coord(rng)};
    out.push_back({p, unit({coord(rng), coord(rng), coord(rng) + 0.01})});
  }
  return out;
}

Qef accumulate(const std::vector<Sample>& samples, Vec3d offset) {
  Qef q;
  for (const Sample& s : samples) q.add(s.p + offset, s.n);
  return q;
}

void expect_same_qef(const Qef& a, const Qef& b, const std::string& what) {
  EXPECT_EQ(a.count, b.count) << what;
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(a.ata[i], b.ata[i], 1e-12) << what << ": ata[" << i << "]";
  expect_near(a.atb, b.atb, 1e-11, what + ": atb");
  EXPECT_NEAR(a.btb, b.btb, 1e-11 * std::max(1.0, b.btb)) << what << ": btb";
  expect_near(a.point_sum, b.point_sum, 1e-11, what + ": point_sum");
  expect_near(a.mass_point(), b.mass_point(), 1e-12, what + ": mass point");
}

TEST(Qef, TranslatedAndMergedAgreeWithAccumulatingTheShiftedSamples) {
  const auto first = random_samples(7, 21), second = random_samples(5, 22);
  const Vec3d d1{12.5, -3.25, 40}, d2{-7, 0.5, 2.75};
  // translated(d) is the QEF of the samples moved by d.
  expect_same_qef(accumulate(first, {}).translated(d1), accumulate(first, d1), "translated");
  expect_same_qef(accumulate(first, d1).translated(-1.0 * d1), accumulate(first, {}),
                  "translated back");
  // Two cells' QEFs in their own local frames, merged in a common one.
  Qef merged = accumulate(first, {}).translated(d1);
  merged.merge(accumulate(second, {}).translated(d2));
  Qef direct = accumulate(first, d1);
  for (const Sample& s : second) direct.add(s.p + d2, s.n);
  expect_same_qef(merged, direct, "merged");
  // error(x) is the sum of squared plane distances, and agrees between the two.
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> coord(-20, 50);
  for (int t = 0; t < 20; ++t) {
    const Vec3d x{coord(rng), coord(rng), coord(rng)};
    double expected = 0;
    for (const Sample& s : first) expected += std::pow(dot(s.n, x - (s.p + d1)), 2);
    for (const Sample& s : second) expected += std::pow(dot(s.n, x - (s.p + d2)), 2);
    EXPECT_NEAR(merged.error(x), expected, 1e-9 * std::max(1.0, expected))
        << "error at point " << t;
    EXPECT_NEAR(direct.error(x), expected, 1e-9 * std::max(1.0, expected))
        << "error at point " << t;
  }
  // And the minimisers agree.
  const QefSolution a = solve_qef(merged, 0.1), b = solve_qef(direct, 0.1);
  EXPECT_EQ(a.rank, b.rank);
  expect_near(a.position, b.position, 1e-9, "minimiser of merged vs direct");
  // Merging an empty QEF changes nothing.
  Qef same = direct;
  same.merge(Qef{});
  expect_same_qef(same, direct, "merge with empty");
}

}  // namespace
}  // namespace segmesh
