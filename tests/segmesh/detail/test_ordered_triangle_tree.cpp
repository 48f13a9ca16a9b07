// The tree on the triangles' own order (detail/ordered_triangle_tree.hpp): exact nearest
// distances whatever the order, the nearest triangle it names, and the Morton order of
// morton_ordered_indices.
#include "segmesh/detail/ordered_triangle_tree.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "segmesh/mesh_distance.hpp"

namespace segmesh {
namespace {

// A soup of n random triangles in [-5, 5]^3, each with its own three corners, in its own order
// and in Morton order.
struct Soup {
  std::vector<Vec3f> pos;
  std::vector<uint32_t> idx, sorted;
  size_t n = 0;
};
Soup soup(size_t n, unsigned seed) {
  Soup s;
  s.n = n;
  std::vector<Vec3f>& pos = s.pos;
  std::vector<uint32_t>& idx = s.idx;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5, 5);
  for (size_t t = 0; t < n; ++t) {
    const Vec3f c{u(rng), u(rng), u(rng)};
    for (int k = 0; k < 3; ++k) {
      idx.push_back(uint32_t(pos.size()));
      pos.push_back({c.x + 0.3f * u(rng), c.y + 0.3f * u(rng), c.z + 0.3f * u(rng)});
    }
  }
  s.sorted = morton_ordered_indices(pos.data(), idx.data(), n);
  return s;
}

double brute_force2(const std::vector<Vec3f>& pos, const std::vector<uint32_t>& idx, Vec3d p) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t t = 0; t < idx.size() / 3; ++t) {
    const Vec3d q = p - closest_point_on_triangle(p, to_double(pos[idx[3 * t]]),
                                                  to_double(pos[idx[3 * t + 1]]),
                                                  to_double(pos[idx[3 * t + 2]]));
    best = std::min(best, dot(q, q));
  }
  return best;
}

TEST(OrderedTriangleTree, NearestEqualsBruteForceAndNamesTheTriangleInEitherOrder) {
  const Soup s = soup(700, 3);
  const std::vector<Vec3f>& pos = s.pos;
  const std::vector<uint32_t>&idx = s.idx, &sorted = s.sorted;
  const size_t n = s.n;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-8, 8);
  for (const std::vector<uint32_t>* order : {&idx, &sorted}) {
    const OrderedTriangleTree tree(pos.data(), order->data(), n);
    size_t hint = OrderedTriangleTree::kNoStart;
    for (int i = 0; i < 300; ++i) {
      const Vec3d p{u(rng), u(rng), u(rng)};
      const double brute = brute_force2(pos, idx, p);
      EXPECT_EQ(tree.nearest2(p), brute);
      // Started and bounded by the last query's triangle, the answer is the same, and the
      // triangle named is at that distance.
      const double bound2 = hint == OrderedTriangleTree::kNoStart
                                ? std::numeric_limits<double>::infinity()
                                : tree.triangle_distance2(p, hint);
      size_t found = hint;
      EXPECT_EQ(tree.nearest2(p, bound2, hint, -1, &found), brute);
      ASSERT_NE(found, OrderedTriangleTree::kNoStart);
      EXPECT_EQ(tree.triangle_distance2(p, found), brute);
      hint = found;
      // Asked only whether the distance is within a value, it answers with a triangle that is.
      size_t within = OrderedTriangleTree::kNoStart;
      const double enough2 = 4 * brute + 1;
      const double d2 = tree.nearest2(p, std::numeric_limits<double>::infinity(),
                                      OrderedTriangleTree::kNoStart, enough2, &within);
      EXPECT_LE(d2, enough2);
      EXPECT_GE(d2, brute);
      ASSERT_NE(within, OrderedTriangleTree::kNoStart);
    }
  }
}

TEST(OrderedTriangleTree, OverlappingListsExactlyTheTrianglesWhoseBoxesMeetTheQuery) {
  const Soup s = soup(3000, 11);
  const OrderedTriangleTree tree(s.pos.data(), s.idx.data(), s.n);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-6, 6), size(0, 3);
  size_t listed = 0;
  for (int q = 0; q < 200; ++q) {
    const Vec3d lo{u(rng), u(rng), u(rng)};
    const Vec3d hi = lo + Vec3d{size(rng), size(rng), size(rng)};
    std::vector<uint32_t> found;
    tree.overlapping(lo, hi, found);
    std::vector<uint32_t> expected;
    for (uint32_t t = 0; t < s.n; ++t) {
      bool meets = true;
      for (int a = 0; a < 3; ++a) {
        double tlo = std::numeric_limits<double>::infinity(), thi = -tlo;
        for (int k = 0; k < 3; ++k) {
          const Vec3f v = s.pos[s.idx[3 * t + k]];
          const double c = a == 0 ? v.x : a == 1 ? v.y : v.z;
          tlo = std::min(tlo, c);
          thi = std::max(thi, c);
        }
        const double qlo = a == 0 ? lo.x : a == 1 ? lo.y : lo.z;
        const double qhi = a == 0 ? hi.x : a == 1 ? hi.y : hi.z;
        meets = meets && tlo <= qhi && qlo <= thi;
      }
      if (meets) expected.push_back(t);
    }
    // In the tree's order, which is the triangles' own: ascending, each once.
    EXPECT_EQ(found, expected) << "query " << q;
    listed += found.size();
  }
  EXPECT_GT(listed, 1000u);  // the queries meet triangles, not only empty space
}

TEST(OrderedTriangleTree, MortonOrderIsAPermutationOfTheTrianglesAndCompactInSpace) {
  const Soup s = soup(4096, 5);
  const std::vector<Vec3f>& pos = s.pos;
  const std::vector<uint32_t>&idx = s.idx, &sorted = s.sorted;
  const size_t n = s.n;
  ASSERT_EQ(sorted.size(), idx.size());
  auto triples = [](const std::vector<uint32_t>& v) {
    std::vector<std::array<uint32_t, 3>> t(v.size() / 3);
    for (size_t k = 0; k < t.size(); ++k) t[k] = {v[3 * k], v[3 * k + 1], v[3 * k + 2]};
    std::sort(t.begin(), t.end());
    return t;
  };
  EXPECT_EQ(triples(sorted), triples(idx));
  // Consecutive triangles are near each other: the mean step between centroids is a small
  // share of the random order's (about 5.2 in a box of side 10).
  auto mean_step = [&](const std::vector<uint32_t>& v) {
    auto centroid = [&](size_t t) {
      return (1.0 / 3.0) * (to_double(pos[v[3 * t]]) + to_double(pos[v[3 * t + 1]]) +
                            to_double(pos[v[3 * t + 2]]));
    };
    double sum = 0;
    for (size_t t = 1; t < n; ++t) sum += norm(centroid(t) - centroid(t - 1));
    return sum / double(n - 1);
  };
  EXPECT_LT(mean_step(sorted), 0.25 * mean_step(idx));
}

TEST(RecentTriangles, KeepsTheLastEightFoundAndBoundsByTheNearest) {
  const Soup s = soup(64, 7);
  const OrderedTriangleTree tree(s.pos.data(), s.idx.data(), s.n);
  RecentTriangles recent;
  const Vec3d p{0.5, -1, 2};
  EXPECT_EQ(recent.first(), OrderedTriangleTree::kNoStart);
  EXPECT_EQ(recent.bound2(tree, p), std::numeric_limits<double>::infinity());
  for (size_t t = 0; t < 12; ++t) recent.add(t);
  recent.add(OrderedTriangleTree::kNoStart);  // ignored
  EXPECT_EQ(recent.first(), 11u);
  // The nearest of triangles 4 to 11 (0 to 3 dropped out), which then comes first.
  double nearest = std::numeric_limits<double>::infinity();
  size_t which = 0;
  for (size_t t = 4; t < 12; ++t)
    if (tree.triangle_distance2(p, t) < nearest) {
      nearest = tree.triangle_distance2(p, t);
      which = t;
    }
  EXPECT_EQ(recent.bound2(tree, p), nearest);
  EXPECT_EQ(recent.first(), which);
  // With a value to reach, the first kept triangle within it answers.
  const double far = recent.bound2(tree, p, std::numeric_limits<double>::max());
  EXPECT_EQ(far, nearest);
  // A triangle added again moves to the front without a second copy: after seven new ones it is
  // kept (and found, which moves it first again), after eight more it is gone.
  const Vec3d corner_of_5 = to_double(s.pos[s.idx[3 * 5]]);
  recent.add(5);
  recent.add(5);
  for (size_t t = 20; t < 27; ++t) recent.add(t);
  EXPECT_EQ(recent.bound2(tree, corner_of_5, 0), 0);
  EXPECT_EQ(recent.first(), 5u);
  for (size_t t = 30; t < 38; ++t) recent.add(t);
  EXPECT_GT(recent.bound2(tree, corner_of_5, 0), 0);
}

}  // namespace
}  // namespace segmesh
