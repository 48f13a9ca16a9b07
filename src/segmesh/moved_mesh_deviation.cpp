#include "segmesh/moved_mesh_deviation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
constexpr float kInfF = std::numeric_limits<float>::infinity();

// Consecutive triangles per leaf: fewer leaves mean less tree to store and walk, more triangles
// per leaf more exact tests per query; 16 measured fastest on the phantom and make_big.py's map.
constexpr size_t kOrderedLeaf = 16;

// A box's squared distance is scaled by this before it is compared: the box bounds are exact
// (minima and maxima of the float corners), so only the rounding of the double sums matters.
constexpr double kBoxShrink = 1 - 1e-12;

// Points searched together (OrderedTree::nearest2_group): enough to share a walk down the tree,
// few enough that they lie close together.
constexpr size_t kGroup = 16;

// Samples per block of the sums and lists: fixed blocks make the results independent of the
// number of threads.
constexpr size_t kSampleBlock = 4096;

// The closest triangles of a mesh, in a tree over the triangles' own order (header comment).
class OrderedTree {
 public:
  OrderedTree(const Vec3f* pos, const uint32_t* idx, size_t n) : pos_(pos), idx_(idx), n_(n) {
    while (((n_ - 1) >> levels_) + 1 > kOrderedLeaf) ++levels_;
    const uint64_t leaves = uint64_t{1} << levels_;
    boxes_.resize(2 * leaves - 1);
    const uint64_t first = leaves - 1;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, leaves),
                      [&](const tbb::blocked_range<uint64_t>& r) {
                        for (uint64_t j = r.begin(); j != r.end(); ++j) {
                          Box b{{kInfF, kInfF, kInfF}, {-kInfF, -kInfF, -kInfF}};
                          for (size_t t = leaf_begin(j); t < leaf_begin(j + 1); ++t)
                            for (int k = 0; k < 3; ++k) b.add(pos_[idx_[3 * t + k]]);
                          boxes_[first + j] = b;
                        }
                      });
    for (int d = levels_ - 1; d >= 0; --d) {
      const uint64_t begin = (uint64_t{1} << d) - 1, end = (uint64_t{2} << d) - 1;
      tbb::parallel_for(tbb::blocked_range<uint64_t>(begin, end, 1024),
                        [&](const tbb::blocked_range<uint64_t>& r) {
                          for (uint64_t i = r.begin(); i != r.end(); ++i) {
                            Box b = boxes_[2 * i + 1];
                            b.merge(boxes_[2 * i + 2]);
                            boxes_[i] = b;
                          }
                        });
    }
  }

  // The squared distance from p to the closest triangle when it is below bound2, else bound2.
  // The search starts with the leaf of triangle `start`, where the closest one usually is.
  // When the start leaf alone brings it to `enough2` or below, that is returned: a caller that
  // only needs to know whether the distance exceeds a value skips the rest of the search.
  double nearest2(Vec3d p, double bound2, size_t start, double enough2 = -1) const {
    double best = bound2;
    const uint64_t first = (uint64_t{1} << levels_) - 1;
    const uint64_t start_leaf = leaf_of(start);
    test_leaf(p, start_leaf, best);
    if (best <= enough2) return best;
    struct Entry {
      uint64_t node;
      double distance2;
    };
    Entry stack[64];
    int top = 0;
    stack[top++] = {0, box_distance2(0, p)};
    while (top > 0) {
      const Entry e = stack[--top];
      if (!(e.distance2 < best)) continue;
      if (e.node >= first) {
        if (e.node - first != start_leaf) test_leaf(p, e.node - first, best);
        continue;
      }
      Entry near{2 * e.node + 1, box_distance2(2 * e.node + 1, p)};
      Entry far{2 * e.node + 2, box_distance2(2 * e.node + 2, p)};
      if (far.distance2 < near.distance2) std::swap(near, far);
      if (far.distance2 < best) stack[top++] = far;
      if (near.distance2 < best) stack[top++] = near;
    }
    return best;
  }

  // The squared distances of a group of nearby points (up to kGroup), each below its bound2[k]
  // (else bound2[k]), each search starting with the leaf of triangle start[k]: after the start
  // leaves, one walk down the tree collects the leaves near the whole group (within each point's
  // best distance so far), and each point tests only those. Samples taken in order are close
  // together, so the group shares one walk where single searches would each make their own.
  // A point whose start leaf brings it to `enough2` or below stops there (see nearest2).
  void nearest2_group(const Vec3d* p, double* bound2, const size_t* start, size_t count,
                      double enough2 = -1) const {
    uint64_t start_leaf[kGroup];
    bool active[kGroup];
    bool any = false;
    Box region{{kInfF, kInfF, kInfF}, {-kInfF, -kInfF, -kInfF}};
    for (size_t k = 0; k < count; ++k) {
      start_leaf[k] = leaf_of(start[k]);
      test_leaf(p[k], start_leaf[k], bound2[k]);
      active[k] = bound2[k] > enough2;
      if (!active[k]) continue;
      any = true;
      // The region holds every point's ball of its best distance (rounded outwards).
      const double r = std::sqrt(bound2[k]) * (1 + 1e-9);
      const double c[3] = {p[k].x, p[k].y, p[k].z};
      for (int a = 0; a < 3; ++a) {
        region.lo[a] = std::min(region.lo[a], std::nextafter(float(c[a] - r), -kInfF));
        region.hi[a] = std::max(region.hi[a], std::nextafter(float(c[a] + r), kInfF));
      }
    }
    if (!any) return;
    const uint64_t first = (uint64_t{1} << levels_) - 1;
    uint64_t stack[64];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const uint64_t node = stack[--top];
      if (!boxes_[node].overlaps(region)) continue;
      if (node < first) {
        stack[top++] = 2 * node + 2;
        stack[top++] = 2 * node + 1;
        continue;
      }
      const uint64_t leaf = node - first;
      for (size_t k = 0; k < count; ++k) {
        if (active[k] && leaf != start_leaf[k] && boxes_[node].distance2(p[k]) < bound2[k]) {
          test_leaf(p[k], leaf, bound2[k]);
        }
      }
    }
  }

 private:
  struct Box {
    float lo[3], hi[3];
    bool overlaps(const Box& o) const {
      for (int a = 0; a < 3; ++a)
        if (lo[a] > o.hi[a] || o.lo[a] > hi[a]) return false;
      return true;
    }
    void add(Vec3f v) {
      const float c[3] = {v.x, v.y, v.z};
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], c[a]);
        hi[a] = std::max(hi[a], c[a]);
      }
    }
    double distance2(Vec3d p) const {
      const double q[3] = {p.x, p.y, p.z};
      double d2 = 0;
      for (int a = 0; a < 3; ++a) {
        const double d = std::max({double(lo[a]) - q[a], q[a] - double(hi[a]), 0.0});
        d2 += d * d;
      }
      return d2 * kBoxShrink;
    }
    void merge(const Box& o) {
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], o.lo[a]);
        hi[a] = std::max(hi[a], o.hi[a]);
      }
    }
  };

  size_t leaf_begin(uint64_t leaf) const { return (leaf * n_) >> levels_; }
  // The leaf j with leaf_begin(j) <= t < leaf_begin(j + 1).
  uint64_t leaf_of(size_t t) const {
    return (((uint64_t{t} + 1) << levels_) + n_ - 1) / n_ - 1;
  }

  double box_distance2(uint64_t node, Vec3d p) const { return boxes_[node].distance2(p); }

  // Each triangle's own box is tried first: most triangles of a leaf are farther than the best
  // distance, and the box rejects them at a fraction of the exact test's cost.
  void test_leaf(Vec3d p, uint64_t leaf, double& best) const {
    for (size_t t = leaf_begin(leaf), end = leaf_begin(leaf + 1); t < end; ++t) {
      const Vec3f fa = pos_[idx_[3 * t]], fb = pos_[idx_[3 * t + 1]], fc = pos_[idx_[3 * t + 2]];
      Box box{{fa.x, fa.y, fa.z}, {fa.x, fa.y, fa.z}};
      box.add(fb);
      box.add(fc);
      if (!(box.distance2(p) < best)) continue;
      const Vec3d q = p - closest_point_on_triangle(p, to_double(fa), to_double(fb), to_double(fc));
      best = std::min(best, dot(q, q));
    }
  }

  const Vec3f* pos_;
  const uint32_t* idx_;
  size_t n_;
  int levels_ = 0;
  std::vector<Box> boxes_;  // complete binary tree in heap order
};

// A fixed pseudo-random choice of samples: sample s is measured for the statistics when its hash
// falls below `threshold` (out of 2^32).
bool chosen(uint64_t s, uint64_t threshold) {
  uint64_t h = (s + 1) * 0x9E3779B97F4A7C15ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return (h & 0xffffffffu) < threshold;
}

struct Direction {
  std::vector<double> distances;  // of the samples measured for the statistics
  double sum = 0;                 // their sum
  double max = 0;                 // the largest distance over every sample
};

// The samples of the surface (from, idx) measured against `target` (the same triangles at the
// positions `to`): sample s < vertex count is vertex s (when a triangle uses it), sample
// vertex count + t the centroid of triangle t.
Direction measure_direction(const std::vector<Vec3f>& from, const std::vector<Vec3f>& to,
                            const std::vector<uint32_t>& idx, const std::vector<uint32_t>& first,
                            size_t used, const OrderedTree& target, size_t statistic_samples) {
  const size_t nv = from.size(), nt = idx.size() / 3, n = nv + nt;
  const size_t count = used + nt;
  const uint64_t threshold = count <= statistic_samples
                                 ? (uint64_t{1} << 32)
                                 : uint64_t((double(statistic_samples) / double(count)) * 4294967296.0);
  // A sample's point, its counterpart's distance and the triangle that starts its search; false
  // for a vertex no triangle uses.
  auto sample = [&](size_t s, Vec3d& p, double& bound, size_t& start) {
    Vec3d q;
    if (s < nv) {
      if (first[s] == kNone) return false;
      p = to_double(from[s]);
      q = to_double(to[s]);
      start = first[s];
    } else {
      const size_t t = s - nv;
      const uint32_t* x = &idx[3 * t];
      p = (1.0 / 3.0) * (to_double(from[x[0]]) + to_double(from[x[1]]) + to_double(from[x[2]]));
      q = (1.0 / 3.0) * (to_double(to[x[0]]) + to_double(to[x[1]]) + to_double(to[x[2]]));
      start = t;
    }
    bound = norm(p - q);
    return true;
  };
  const size_t blocks = (n + kSampleBlock - 1) / kSampleBlock;
  std::vector<std::vector<double>> block_distances(blocks);
  std::vector<double> block_sum(blocks, 0.0), block_max(blocks, 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      double sum = 0, max = 0;
      std::vector<double>& out = block_distances[b];
      Vec3d p[kGroup];
      double best2[kGroup];
      size_t start[kGroup];
      size_t count = 0;
      auto flush = [&] {
        target.nearest2_group(p, best2, start, count);
        for (size_t k = 0; k < count; ++k) {
          const double d = std::sqrt(best2[k]);
          out.push_back(d);
          sum += d;
          max = std::max(max, d);
        }
        count = 0;
      };
      for (size_t s = b * kSampleBlock, end = std::min(n, (b + 1) * kSampleBlock); s < end; ++s) {
        double bound;
        if (!chosen(s, threshold) || !sample(s, p[count], bound, start[count])) continue;
        best2[count] = bound * bound;
        if (++count == kGroup) flush();
      }
      if (count > 0) flush();
      block_sum[b] = sum;
      block_max[b] = max;
    }
  });
  Direction dir;
  size_t measured = 0;
  for (size_t b = 0; b < blocks; ++b) {
    dir.sum += block_sum[b];
    dir.max = std::max(dir.max, block_max[b]);
    measured += block_distances[b].size();
  }
  dir.distances.reserve(measured);
  for (auto& d : block_distances) {
    dir.distances.insert(dir.distances.end(), d.begin(), d.end());
    d = {};
  }
  if (threshold >> 32) return dir;

  // The largest distance over the samples not measured yet: only those whose counterpart is
  // farther than the largest distance found can exceed it. The few with the largest bounds are
  // searched first, alone, to raise the largest distance early; then the rest still above it, in
  // sample order and in groups, each stopping at its start leaf when that shows it is no larger.
  struct Candidate {
    double bound;
    size_t sample;
  };
  std::vector<std::vector<Candidate>> block_candidates(blocks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b)
      for (size_t s = b * kSampleBlock, end = std::min(n, (b + 1) * kSampleBlock); s < end; ++s) {
        Vec3d p;
        double bound;
        size_t start;
        if (chosen(s, threshold) || !sample(s, p, bound, start)) continue;
        if (bound > dir.max) block_candidates[b].push_back({bound, s});
      }
  });
  std::vector<Candidate> largest;
  for (const auto& c : block_candidates) largest.insert(largest.end(), c.begin(), c.end());
  constexpr size_t kFirst = 1024;
  auto by_bound = [](const Candidate& a, const Candidate& b) {
    return a.bound > b.bound || (a.bound == b.bound && a.sample < b.sample);
  };
  if (largest.size() > kFirst) {
    std::nth_element(largest.begin(), largest.begin() + kFirst, largest.end(), by_bound);
    largest.resize(kFirst);
  }
  std::vector<double> found(largest.size(), 0.0);
  tbb::parallel_for(size_t{0}, largest.size(), [&](size_t c) {
    Vec3d p;
    double bound;
    size_t start;
    sample(largest[c].sample, p, bound, start);
    found[c] = std::sqrt(target.nearest2(p, bound * bound, start, dir.max * dir.max));
  });
  for (double d : found) dir.max = std::max(dir.max, d);
  const double max = dir.max;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      Vec3d p[kGroup];
      double best2[kGroup];
      size_t start[kGroup];
      size_t count = 0;
      double block = 0;
      auto flush = [&] {
        target.nearest2_group(p, best2, start, count, max * max);
        for (size_t k = 0; k < count; ++k) block = std::max(block, std::sqrt(best2[k]));
        count = 0;
      };
      for (const Candidate& c : block_candidates[b]) {
        if (!(c.bound > max)) continue;
        double bound;
        sample(c.sample, p[count], bound, start[count]);
        best2[count] = bound * bound;
        if (++count == kGroup) flush();
      }
      if (count > 0) flush();
      block_max[b] = block;
    }
  });
  for (size_t b = 0; b < blocks; ++b) dir.max = std::max(dir.max, block_max[b]);
  return dir;
}

}  // namespace

Deviation moved_mesh_deviation(const std::vector<Vec3f>& before, const TriMesh& after,
                               size_t statistic_samples) {
  const std::vector<uint32_t>& idx = after.indices;
  const size_t nt = after.triangle_count(), nv = after.positions.size();
  if (nt == 0) return {0, 0, 0};
  // One triangle of every used vertex (the smallest id, whatever the schedule): where its search
  // starts.
  std::vector<uint32_t> first(nv, kNone);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nt), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t)
      for (int k = 0; k < 3; ++k) {
        std::atomic_ref<uint32_t> slot(first[idx[3 * t + k]]);
        uint32_t seen = slot.load(std::memory_order_relaxed);
        while (t < seen && !slot.compare_exchange_weak(seen, uint32_t(t), std::memory_order_relaxed)) {
        }
      }
  });
  const size_t used = size_t(std::count_if(first.begin(), first.end(), [](uint32_t t) { return t != kNone; }));
  std::optional<OrderedTree> tree_before, tree_after;
  tbb::parallel_invoke([&] { tree_before.emplace(before.data(), idx.data(), nt); },
                       [&] { tree_after.emplace(after.positions.data(), idx.data(), nt); });
  Direction ab = measure_direction(before, after.positions, idx, first, used, *tree_after,
                                   statistic_samples);
  tree_after.reset();
  Direction ba = measure_direction(after.positions, before, idx, first, used, *tree_before,
                                   statistic_samples);
  Deviation dev;
  // One addition of two partial sums is commutative, which makes the mean exactly symmetric.
  dev.mean = (ab.sum + ba.sum) / double(ab.distances.size() + ba.distances.size());
  dev.hausdorff = std::max(ab.max, ba.max);
  ab.distances.insert(ab.distances.end(), ba.distances.begin(), ba.distances.end());
  ba.distances = {};
  dev.p95 = percentile(ab.distances, 0.95);
  return dev;
}

}  // namespace segmesh
