#include "segmesh/moved_mesh_deviation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

#include "segmesh/detail/deviation_strata.hpp"
#include "segmesh/detail/ordered_triangle_tree.hpp"

namespace segmesh {

namespace {

// Chosen samples up to this many ids apart are searched in groups of kTreeGroup (one walk for
// the group: they are still near each other on the surface); farther apart, one by one
// (docs/PERFORMANCE.md).
constexpr size_t kGroupStride = 16;

// The samples of the two surfaces: the mesh's triangles over the positions `before` and `after`.
// Sample s < vertex count is vertex s (when a triangle uses it), sample vertex count + t the
// centroid of triangle t; `forward` measures the samples of `before` against `after`, otherwise
// the other way round. The statistics take one sample per stratum of `stride` consecutive ids
// (every sample when the stride is 1), at a fixed pseudo-random place in the stratum, the same in
// both directions.
struct Samples {
  const std::vector<Vec3f>& before;
  const std::vector<Vec3f>& after;
  const std::vector<uint32_t>& idx;
  const std::vector<uint32_t>& first;
  size_t stride = 1;

  size_t vertices() const { return before.size(); }
  size_t count() const { return before.size() + idx.size() / 3; }
  bool chosen(size_t s) const { return stratum_chosen(s, stride); }

  // Sample s's point on its surface, its counterpart's distance (which bounds its own: the
  // counterpart lies on the other surface) and the triangle that starts its search; false for a
  // vertex no triangle uses.
  bool get(size_t s, bool forward, Vec3d& p, double& bound, size_t& start) const {
    const std::vector<Vec3f>& from = forward ? before : after;
    const std::vector<Vec3f>& to = forward ? after : before;
    Vec3d q;
    if (s < vertices()) {
      if (first[s] == kNoTriangle) return false;
      p = to_double(from[s]);
      q = to_double(to[s]);
      start = first[s];
    } else {
      const size_t t = s - vertices();
      const uint32_t* x = &idx[3 * t];
      p = (1.0 / 3.0) * (to_double(from[x[0]]) + to_double(from[x[1]]) + to_double(from[x[2]]));
      q = (1.0 / 3.0) * (to_double(to[x[0]]) + to_double(to[x[1]]) + to_double(to[x[2]]));
      start = t;
    }
    bound = norm(p - q);
    return true;
  }
};

// The chosen samples of one direction, each measured exactly against `target`, searched in
// groups of kTreeGroup consecutive chosen ones up to a stride of kGroupStride (close together:
// the samples follow the vertex and triangle order), each below its counterpart's distance and
// starting at its start leaf.
SampleDistances measure_statistics(const Samples& samples, bool forward,
                                   const OrderedTriangleTree& target) {
  return measure_in_blocks(samples.count(), [&](size_t begin, size_t end, std::vector<double>& out) {
    Vec3d p[kTreeGroup];
    double best2[kTreeGroup];
    size_t start[kTreeGroup];
    size_t count = 0;
    auto flush = [&] {
      if (samples.stride <= kGroupStride) {
        target.nearest2_group(p, best2, start, count);
      } else {
        for (size_t k = 0; k < count; ++k) best2[k] = target.nearest2(p[k], best2[k], start[k]);
      }
      for (size_t k = 0; k < count; ++k) out.push_back(std::sqrt(best2[k]));
      count = 0;
    };
    for_each_chosen(begin, end, samples.stride, [&](size_t s) {
      double bound;
      if (!samples.get(s, forward, p[count], bound, start[count])) return;
      best2[count] = bound * bound;
      if (++count == kTreeGroup) flush();
    });
    if (count > 0) flush();
  });
}

// The largest distance over every sample of both directions, given `largest`: the largest
// found among the measured ones. A sample's counterpart distance bounds its own (in both
// directions: it is the same), so only the samples not measured whose bound exceeds the largest
// distance found can change it. The kFirst with the largest bounds are searched first, to raise
// it early; then the rest still above it, each search ending as soon as a triangle within the
// largest distance shows that the sample does not exceed it.
double largest_distance(const Samples& samples, const OrderedTriangleTree& after_tree,
                        const OrderedTriangleTree& before_tree, double largest) {
  // 8 bytes a candidate (on make_big.py's bone about a million): its bound rounded up to float
  // (a conservative filter; the search recomputes it) and its place in its block.
  struct Candidate {
    float bound;
    uint32_t offset;
  };
  const size_t n = samples.count();
  const size_t blocks = (n + kDeviationSampleBlock - 1) / kDeviationSampleBlock;
  std::vector<std::vector<Candidate>> block_candidates(blocks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      std::vector<Candidate>& out = block_candidates[b];
      for (size_t s = b * kDeviationSampleBlock, end = std::min(n, (b + 1) * kDeviationSampleBlock); s < end; ++s) {
        Vec3d p;
        double bound;
        size_t start;
        if (samples.chosen(s) || !samples.get(s, true, p, bound, start) || !(bound > largest)) continue;
        float up = float(bound);
        if (double(up) < bound) up = std::nextafter(up, std::numeric_limits<float>::infinity());
        out.push_back({up, uint32_t(s - b * kDeviationSampleBlock)});
      }
      out.shrink_to_fit();
    }
  });
  // Sample s in both directions: the largest of its two distances where one exceeds `below`,
  // otherwise a value no larger than `below`.
  auto search = [&](size_t s, double below) {
    double d2 = 0;
    for (bool forward : {true, false}) {
      Vec3d p;
      double bound = 0;
      size_t start = 0;
      samples.get(s, forward, p, bound, start);
      const OrderedTriangleTree& target = forward ? after_tree : before_tree;
      d2 = std::max(d2, target.nearest2(p, bound * bound, start, std::max(below * below, d2)));
    }
    return std::sqrt(d2);
  };
  // The bound of the kFirst-th candidate: those at or above it go first.
  constexpr size_t kFirst = 1024;
  float first = 0;
  {
    std::vector<float> bounds;
    for (const auto& c : block_candidates)
      for (const Candidate& x : c) bounds.push_back(x.bound);
    if (bounds.size() > kFirst) {
      std::nth_element(bounds.begin(), bounds.begin() + (kFirst - 1), bounds.end(), std::greater<>());
      first = bounds[kFirst - 1];
    }
  }
  std::vector<double> block_max(blocks, 0.0);
  for (bool early : {true, false}) {
    const double below = largest;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t b = r.begin(); b != r.end(); ++b) {
        double block = 0;
        for (const Candidate& c : block_candidates[b])
          if ((c.bound >= first) == early && c.bound > below)
            block = std::max(block, search(b * kDeviationSampleBlock + c.offset, below));
        block_max[b] = std::max(block_max[b], block);
      }
    });
    for (double d : block_max) largest = std::max(largest, d);
  }
  return largest;
}

}  // namespace

Deviation moved_mesh_deviation(const std::vector<Vec3f>& before, const TriMesh& after,
                               size_t statistic_samples) {
  const std::vector<uint32_t>& idx = after.indices;
  const size_t nt = after.triangle_count(), nv = after.positions.size();
  if (nt == 0) return {0, 0, 0};
  // One triangle of every used vertex: where its search starts.
  const std::vector<uint32_t> first = first_triangles(idx.data(), nt, nv);
  Samples samples{before, after.positions, idx, first};
  samples.stride = stratum_stride(samples.count(), statistic_samples);
  std::optional<OrderedTriangleTree> tree_before, tree_after;
  tbb::parallel_invoke([&] { tree_before.emplace(before.data(), idx.data(), nt); },
                       [&] { tree_after.emplace(after.positions.data(), idx.data(), nt); });
  SampleDistances ab = measure_statistics(samples, true, *tree_after);
  SampleDistances ba = measure_statistics(samples, false, *tree_before);
  double hausdorff = std::max(ab.max, ba.max);
  if (samples.stride > 1) hausdorff = largest_distance(samples, *tree_after, *tree_before, hausdorff);
  return pooled_deviation(std::move(ab), std::move(ba), hausdorff);
}

}  // namespace segmesh
