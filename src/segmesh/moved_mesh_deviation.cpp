#include "segmesh/moved_mesh_deviation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <optional>

#include "segmesh/detail/ordered_triangle_tree.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();

// Samples per block of the sums and lists: fixed blocks make the results independent of the
// number of threads.
constexpr size_t kSampleBlock = 4096;

// A fixed pseudo-random choice of samples: sample s is measured for the statistics when its hash
// falls below `threshold` (out of 2^32).
bool chosen(uint64_t s, uint64_t threshold) {
  uint64_t h = (s + 1) * 0x9E3779B97F4A7C15ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return (h & 0xffffffffu) < threshold;
}

// Searches the samples that `each` offers (each(add) calls add(s) for every sample id s to
// search; sample(s, p, bound, start) as in measure_direction) in groups of kTreeGroup, each below
// its counterpart's distance, stopping at its start leaf when that brings it to `enough2`; calls
// found(distance) for each, in the order offered.
template <class Each, class Sample, class Found>
void search_in_groups(const OrderedTriangleTree& target, Each&& each, Sample&& sample,
                      double enough2, Found&& found) {
  Vec3d p[kTreeGroup];
  double best2[kTreeGroup];
  size_t start[kTreeGroup];
  size_t count = 0;
  auto flush = [&] {
    target.nearest2_group(p, best2, start, count, enough2);
    for (size_t k = 0; k < count; ++k) found(std::sqrt(best2[k]));
    count = 0;
  };
  each([&](size_t s) {
    double bound;
    if (!sample(s, p[count], bound, start[count])) return;
    best2[count] = bound * bound;
    if (++count == kTreeGroup) flush();
  });
  if (count > 0) flush();
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
                            size_t used, const OrderedTriangleTree& target,
                            size_t statistic_samples) {
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
      search_in_groups(
          target,
          [&](auto&& add) {
            for (size_t s = b * kSampleBlock, end = std::min(n, (b + 1) * kSampleBlock); s < end; ++s)
              if (chosen(s, threshold)) add(s);
          },
          sample, -1, [&](double d) {
            out.push_back(d);
            sum += d;
            max = std::max(max, d);
          });
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
      double block = 0;
      search_in_groups(
          target,
          [&](auto&& add) {
            for (const Candidate& c : block_candidates[b])
              if (c.bound > max) add(c.sample);
          },
          sample, max * max, [&](double d) { block = std::max(block, d); });
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
  std::optional<OrderedTriangleTree> tree_before, tree_after;
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
