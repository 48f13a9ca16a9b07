// Gaussian pre-smoothing: normalisation, mass and symmetry, the kernel against the sampled analytic
// Gaussian per axis on an anisotropic grid, the flat step, a direct reference with every boundary
// case, determinism across thread counts, the margin, and what smoothing does to meshed volumes.
#include "segmesh/gaussian_filter.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <iostream>
#include <numbers>
#include <random>

#include "segmesh/error.hpp"
#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"

namespace segmesh {
namespace {

// The sampled Gaussian of `sigma` voxels on taps -r..r, r = ceil(3 sigma), normalised to sum 1;
// index t + r holds tap t.
std::vector<double> sampled_gaussian(double sigma) {
  const int r = static_cast<int>(std::ceil(3 * sigma - 1e-9));
  std::vector<double> w(2 * r + 1);
  double sum = 0;
  for (int t = -r; t <= r; ++t) sum += w[t + r] = std::exp(-t * t / (2 * sigma * sigma));
  for (double& x : w) x /= sum;
  return w;
}

template <class T>
Volume<T> make_volume(std::array<int64_t, 3> dims, std::array<double, 3> spacing, T value = T{}) {
  Volume<T> v;
  v.grid.dims = dims;
  v.grid.spacing = spacing;
  v.voxels.assign(v.grid.voxel_count(), value);
  return v;
}

Volume<float> random_volume(std::array<int64_t, 3> dims, std::array<double, 3> spacing,
                            unsigned seed) {
  auto v = make_volume<float>(dims, spacing);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(-100.0f, 100.0f);
  for (float& x : v.voxels) x = value(rng);
  return v;
}

// The separable filter computed directly, in double, one axis at a time, reading `outside` beyond
// the volume.
Volume<double> reference_filter(const Volume<float>& v, double sigma_mm, double outside) {
  Volume<double> cur;
  cur.grid = v.grid;
  cur.voxels.assign(v.voxels.begin(), v.voxels.end());
  const auto& d = v.grid.dims;
  for (int a = 0; a < 3; ++a) {
    const double sigma = sigma_mm / v.grid.spacing[a];
    if (sigma < kGaussianMinSigmaVoxels) continue;
    const auto w = sampled_gaussian(sigma);
    const int r = static_cast<int>(w.size() / 2);
    Volume<double> next = cur;
    for (int64_t k = 0; k < d[2]; ++k)
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i) {
          double sum = 0;
          for (int t = -r; t <= r; ++t) {
            std::array<int64_t, 3> p{i, j, k};
            p[a] += t;
            const bool in = p[a] >= 0 && p[a] < d[a];
            sum += w[t + r] * (in ? cur.at(p[0], p[1], p[2]) : outside);
          }
          next.at(i, j, k) = sum;
        }
    cur = std::move(next);
  }
  return cur;
}

TEST(GaussianFilter, ConstantVolumeStaysConstant) {
  const auto v = make_volume<float>({17, 9, 6}, {0.4, 0.7, 2.0}, 3.5f);
  for (double sigma : {0.3, 1.0, 2.5, 10.0}) {
    const auto out = gaussian_filter(v, sigma, 3.5f);
    for (float x : out.voxels) ASSERT_NEAR(x, 3.5f, 1e-5f) << "sigma " << sigma;
  }
  // A thin or single-voxel axis, the kernel reaching far beyond it on both sides.
  for (std::array<int64_t, 3> dims : {std::array<int64_t, 3>{5, 1, 3}, {1, 1, 1}, {1, 4, 1}}) {
    const auto out = gaussian_filter(make_volume<int32_t>(dims, {1, 1, 1}, 7), 2.0, 7.0f);
    ASSERT_EQ(out.voxels.size(), out.grid.voxel_count());
    for (float x : out.voxels) ASSERT_NEAR(x, 7.0f, 1e-5f);
  }
}

TEST(GaussianFilter, SingleVoxelVolumeKeepsTheCentreWeight) {
  // Every neighbour is `outside` (0): what is left is the product of the three centre weights.
  auto v = make_volume<uint8_t>({1, 1, 1}, {0.5, 1.0, 2.0}, 1);
  const double sigma_mm = 1.5;
  const auto out = gaussian_filter(v, sigma_mm);
  double expected = 1;
  for (int a = 0; a < 3; ++a) {
    const auto w = sampled_gaussian(sigma_mm / v.grid.spacing[a]);
    expected *= w[w.size() / 2];
  }
  EXPECT_NEAR(out.voxels[0], expected, 1e-6);
}

TEST(GaussianFilter, ImpulseResponseHasUnitMassAndIsSymmetric) {
  for (double sigma : {0.5, 1.0, 1.7, 3.0}) {
    const int64_t r = static_cast<int64_t>(std::ceil(3 * sigma - 1e-9));
    const int64_t n = 2 * r + 5, c = n / 2;  // the kernel fits inside
    auto v = make_volume<uint8_t>({n, n, n}, {1, 1, 1});
    v.at(c, c, c) = 1;
    const auto out = gaussian_filter(v, sigma);
    double mass = 0;
    for (float x : out.voxels) mass += x;
    EXPECT_NEAR(mass, 1.0, 1e-5) << "sigma " << sigma;
    for (int64_t k = 0; k < n; ++k)
      for (int64_t j = 0; j < n; ++j)
        for (int64_t i = 0; i < n; ++i) {
          const float x = out.at(i, j, k);
          ASSERT_EQ(x, out.at(2 * c - i, j, k)) << i << " " << j << " " << k;
          ASSERT_EQ(x, out.at(i, 2 * c - j, k)) << i << " " << j << " " << k;
          ASSERT_EQ(x, out.at(i, j, 2 * c - k)) << i << " " << j << " " << k;
          ASSERT_NEAR(x, out.at(j, i, k), 1e-7);  // isotropic grid: the axes agree
        }
  }
}

TEST(GaussianFilter, ImpulseResponseIsTheSampledGaussianOnEachAxisOfAnAnisotropicGrid) {
  // 1.5 mm on spacings 0.5, 0.8, 1.5 mm: sigma 3, 1.875, 1 voxels, radii 9, 6, 3.
  const std::array<double, 3> spacing{0.5, 0.8, 1.5};
  const double sigma_mm = 1.5;
  std::array<std::vector<double>, 3> w;
  for (int a = 0; a < 3; ++a) w[a] = sampled_gaussian(sigma_mm / spacing[a]);
  const std::array<int64_t, 3> r{9, 6, 3};
  for (int a = 0; a < 3; ++a) ASSERT_EQ(static_cast<int64_t>(w[a].size()), 2 * r[a] + 1);

  Grid grid;
  grid.spacing = spacing;
  EXPECT_EQ(gaussian_radius(grid, sigma_mm), r);

  const std::array<int64_t, 3> dims{2 * r[0] + 7, 2 * r[1] + 7, 2 * r[2] + 7};
  const std::array<int64_t, 3> c{r[0] + 3, r[1] + 3, r[2] + 3};
  auto v = make_volume<float>(dims, spacing);
  v.at(c[0], c[1], c[2]) = 1;
  const auto out = gaussian_filter(v, sigma_mm);
  double worst = 0;
  for (int64_t k = 0; k < dims[2]; ++k)
    for (int64_t j = 0; j < dims[1]; ++j)
      for (int64_t i = 0; i < dims[0]; ++i) {
        const std::array<int64_t, 3> d{i - c[0], j - c[1], k - c[2]};
        double expected = 1;
        for (int a = 0; a < 3; ++a)
          expected *= std::abs(d[a]) <= r[a] ? w[a][d[a] + r[a]] : 0.0;
        if (expected == 0) {
          ASSERT_EQ(out.at(i, j, k), 0.0f) << "beyond the truncation at " << i << " " << j << " " << k;
        }
        worst = std::max(worst, std::abs(out.at(i, j, k) - expected) / w[0][r[0]]);
      }
  // Relative to the largest 1-D weight, i.e. float rounding only.
  EXPECT_LT(worst, 1e-5);
}

TEST(GaussianFilter, HalfSpaceStepKeepsOneHalfAtTheStep) {
  // A flat boundary does not move: the two voxels beside the step sum to 1, so the 0.5 crossing
  // of their linear interpolation is exactly at the step, for any sigma and on each axis.
  for (int axis = 0; axis < 3; ++axis) {
    for (double sigma : {0.3, 0.7, 1.0, 2.5, 4.0}) {
      std::array<int64_t, 3> dims{27, 27, 27};
      dims[axis] = 60;
      auto v = make_volume<uint8_t>(dims, {1, 1, 1});
      for (int64_t k = 0; k < dims[2]; ++k)
        for (int64_t j = 0; j < dims[1]; ++j)
          for (int64_t i = 0; i < dims[0]; ++i) v.at(i, j, k) = std::array{i, j, k}[axis] < 30;
      const auto out = gaussian_filter(v, sigma);
      std::array<int64_t, 3> below{13, 13, 13}, above{13, 13, 13};  // beyond reach of the sides
      below[axis] = 29;
      above[axis] = 30;
      const float a = out.at(below[0], below[1], below[2]);
      const float b = out.at(above[0], above[1], above[2]);
      EXPECT_NEAR(a + b, 1.0f, 1e-6f) << "axis " << axis << " sigma " << sigma;
      EXPECT_GT(a, 0.5f);
      EXPECT_LT(b, 0.5f);
      if (sigma >= 1) {
        EXPECT_LT(a, 0.99f) << "the step was not smoothed";
      }
    }
  }
}

TEST(GaussianFilter, MatchesADirectReferenceIncludingBordersAndSplitRows) {
  // nz = 1100 makes the z pass split rows into blocks; ny = 2 is far thinner than its kernel.
  const auto v = random_volume({300, 2, 1100}, {1.0, 0.5, 2.0}, 11);
  const double sigma_mm = 1.2;  // 1.2, 2.4, 0.6 voxels
  const float outside = 0.25f;
  const auto out = gaussian_filter(v, sigma_mm, outside);
  const auto ref = reference_filter(v, sigma_mm, outside);
  double worst = 0;
  for (size_t n = 0; n < ref.voxels.size(); ++n)
    worst = std::max(worst, std::abs(out.voxels[n] - ref.voxels[n]));
  EXPECT_LT(worst, 1e-4);  // values up to 100: float rounding

  // The same on small volumes with axes of one voxel.
  for (std::array<int64_t, 3> dims : {std::array<int64_t, 3>{1, 7, 5}, {6, 1, 4}, {5, 3, 1}}) {
    const auto small = random_volume(dims, {0.6, 0.9, 1.3}, 5);
    const auto o = gaussian_filter(small, 1.0, -2.0f);
    const auto rf = reference_filter(small, 1.0, -2.0);
    for (size_t n = 0; n < rf.voxels.size(); ++n) ASSERT_NEAR(o.voxels[n], rf.voxels[n], 1e-4);
  }
}

TEST(GaussianFilter, OutputIsIdenticalForAnyThreadCount) {
  const auto v = random_volume({83, 61, 47}, {0.6, 0.7, 1.4}, 3);
  Volume<float> one, many;
  tbb::task_arena(1).execute([&] { one = gaussian_filter(v, 1.3, -7.0f); });
  tbb::task_arena(4).execute([&] { many = gaussian_filter(v, 1.3, -7.0f); });
  ASSERT_EQ(one.voxels.size(), many.voxels.size());
  EXPECT_TRUE(one.voxels == many.voxels);
  EXPECT_FALSE(one.voxels == v.voxels);  // it did filter
}

TEST(GaussianFilter, SigmaZeroIsTheIdentity) {
  auto v = make_volume<int32_t>({13, 7, 5}, {0.5, 0.5, 3.0});
  std::mt19937 rng(1);
  std::uniform_int_distribution<int32_t> value(-1024, 3071);
  for (int32_t& x : v.voxels) x = value(rng);
  // sigma 0.04 mm is 0.08 voxels on x and y: below the threshold on every axis.
  for (double sigma : {0.0, -1.0, std::nan(""), 0.04}) {
    const auto out = gaussian_filter(v, sigma, 55.0f);
    ASSERT_EQ(out.voxels.size(), v.voxels.size());
    for (size_t n = 0; n < v.voxels.size(); ++n)
      ASSERT_EQ(out.voxels[n], static_cast<float>(v.voxels[n])) << "sigma " << sigma;
    EXPECT_EQ(out.grid.dims, v.grid.dims);
    EXPECT_EQ(out.grid.spacing, v.grid.spacing);
  }
  // 0.06 mm is 0.12 voxels on x and y (filtered, if faintly), 0.02 on z (left alone).
  EXPECT_EQ(gaussian_radius(v.grid, 0.06), (std::array<int64_t, 3>{1, 1, 0}));
  auto impulse = make_volume<uint8_t>({3, 3, 3}, v.grid.spacing);
  impulse.at(1, 1, 1) = 1;
  const auto out = gaussian_filter(impulse, 0.06);
  EXPECT_GT(out.at(2, 1, 1), 0.0f);
  EXPECT_GT(out.at(1, 0, 1), 0.0f);
  EXPECT_EQ(out.at(1, 1, 2), 0.0f);
}

TEST(GaussianFilter, MarginKeepsTwoLayersOfBackground) {
  Grid grid;
  grid.spacing = {0.197, 0.197, 2.0};
  EXPECT_EQ(gaussian_margin(grid, 0.3), (std::array<int64_t, 3>{7, 7, 3}));  // ceil(4.57), ceil(0.45)
  EXPECT_EQ(gaussian_margin(grid, 0.0), (std::array<int64_t, 3>{2, 2, 2}));
  grid.spacing = {1, 1, 1};
  EXPECT_EQ(gaussian_margin(grid, 1.0), (std::array<int64_t, 3>{5, 5, 5}));
  grid.spacing = {0.5, 1, 2};
  EXPECT_EQ(gaussian_margin(grid, 1.5), (std::array<int64_t, 3>{11, 7, 5}));

  // A box of ones with exactly the margin around it: after smoothing the outer two layers are still
  // pure background and the third is not (the margin is sufficient and tight).
  const auto m = gaussian_margin(grid, 1.5);
  const std::array<int64_t, 3> inner{6, 5, 4};
  auto v = make_volume<uint8_t>({inner[0] + 2 * m[0], inner[1] + 2 * m[1], inner[2] + 2 * m[2]},
                                grid.spacing);
  for (int64_t k = 0; k < inner[2]; ++k)
    for (int64_t j = 0; j < inner[1]; ++j)
      for (int64_t i = 0; i < inner[0]; ++i) v.at(i + m[0], j + m[1], k + m[2]) = 1;
  const auto out = gaussian_filter(v, 1.5);
  const auto& d = out.grid.dims;
  for (int axis = 0; axis < 3; ++axis) {
    float layer_max[3] = {0, 0, 0};
    for (int64_t k = 0; k < d[2]; ++k)
      for (int64_t j = 0; j < d[1]; ++j)
        for (int64_t i = 0; i < d[0]; ++i) {
          const int64_t p = std::array{i, j, k}[axis];
          const int64_t layer = std::min(p, d[axis] - 1 - p);
          if (layer < 3) layer_max[layer] = std::max(layer_max[layer], out.at(i, j, k));
        }
    EXPECT_EQ(layer_max[0], 0.0f) << "axis " << axis;
    EXPECT_EQ(layer_max[1], 0.0f) << "axis " << axis;
    EXPECT_GT(layer_max[2], 0.0f) << "axis " << axis;
  }
}

TEST(GaussianFilter, ReportsProgressAndCancels) {
  struct Recorder : Progress {
    std::atomic<double> last{0};
    bool cancel = false;
    void update(double f) override {
      double seen = last.load();
      while (f > seen && !last.compare_exchange_weak(seen, f)) {
      }
    }
    bool cancelled() const override { return cancel; }
  };
  const auto v = random_volume({20, 20, 20}, {1, 1, 1}, 2);
  Recorder done;
  gaussian_filter(v, 1.0, 0.0f, done);
  EXPECT_DOUBLE_EQ(done.last.load(), 1.0);
  Recorder stop;
  stop.cancel = true;
  EXPECT_THROW(gaussian_filter(v, 1.0, 0.0f, stop), Cancelled);
}

// Smoothes a 0/1 indicator with `sigma_voxels`, meshes it at 0.5 and returns the enclosed volume in
// voxel units (the grid's spacing is 0.8 mm, so millimetres are exercised too).
double smoothed_mesh_volume(Volume<uint8_t> indicator, double sigma_voxels) {
  const double h = indicator.grid.spacing[0];
  const Volume<float> field = gaussian_filter(indicator, sigma_voxels * h);
  const MeshMeasures m = measure_mesh(marching_cubes(field, {.iso = 0.5}));
  EXPECT_TRUE(m.closed());
  return m.volume_mm3 / (h * h * h);
}

TEST(GaussianFilter, SmoothedBallKeepsItsVolume) {
  // A ball of radius 20 voxels, sigma 1 voxel: the 0.5 surface should move in by about
  // sigma^2 / R = 0.05 voxels, -3 sigma^2 / R^2 = -0.75 % of the volume.
  const double radius = 20, sigma = 1;
  const int64_t n = 2 * (20 + 12) + 1, c = n / 2;
  auto v = make_volume<uint8_t>({n, n, n}, {0.8, 0.8, 0.8});
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i) {
        const double x = double(i - c), y = double(j - c), z = double(k - c);
        v.at(i, j, k) = x * x + y * y + z * z <= radius * radius;
      }
  const double analytic = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  const double voxels = static_cast<double>(std::count(v.voxels.begin(), v.voxels.end(), 1));
  const double binary = smoothed_mesh_volume(v, 0);
  const double smoothed = smoothed_mesh_volume(v, sigma);
  const double change = smoothed / analytic - 1;
  const double predicted = -3 * sigma * sigma / (radius * radius);
  std::cout << "[ measure  ] ball R=20 voxels: voxel count " << 100 * (voxels / analytic - 1)
            << " %, binary MC " << 100 * (binary / analytic - 1) << " %, smoothed (sigma 1 voxel) "
            << 100 * change << " % of the analytic ball; smoothed vs voxel count "
            << 100 * (smoothed / voxels - 1) << " % (predicted " << 100 * predicted << " %)\n";
  EXPECT_LT(std::abs(change), 0.02);
  EXPECT_LT(change, 0.0) << "a convex part shrinks";
  // Against the label's own volume the shrinkage is the curvature term sigma^2 / R, give or take
  // the chords of Marching Cubes.
  EXPECT_NEAR(smoothed / voxels - 1, predicted, 0.003);
}

TEST(GaussianFilter, SmoothedThinSlabLosesPartOfItsVolume) {
  // 40 x 40 x 2 voxels: a slab thinner than 2 sigma loses a large share of its volume.
  const int64_t pad = 8;
  auto v = make_volume<uint8_t>({40 + 2 * pad, 40 + 2 * pad, 2 + 2 * pad}, {0.8, 0.8, 0.8});
  for (int64_t k = pad; k < pad + 2; ++k)
    for (int64_t j = pad; j < pad + 40; ++j)
      for (int64_t i = pad; i < pad + 40; ++i) v.at(i, j, k) = 1;
  const double label = 40.0 * 40.0 * 2.0;
  const double binary = smoothed_mesh_volume(v, 0);
  const double smoothed = smoothed_mesh_volume(v, 1.0);
  const double loss = 1 - smoothed / label;
  std::cout << "[ measure  ] slab 40x40x2 voxels: binary MC " << 100 * (binary / label - 1)
            << " %, smoothed (sigma 1 voxel) " << -100 * loss << " %\n";
  EXPECT_GT(loss, 0.0);
  EXPECT_LT(loss, 0.40);
}

}  // namespace
}  // namespace segmesh
