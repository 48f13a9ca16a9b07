// The samples of the deviation statistics (moved_mesh_deviation.hpp, mesh_deviation in
// mesh_distance.hpp), shared by both: measured in fixed blocks, and above a limit stratified: the
// mean and the 95th percentile are taken over one sample in every stratum of `stride` consecutive
// sample ids (neighbours on the surface), at a fixed pseudo-random place in it, the same for any
// thread count; both directions' distances pooled into one Deviation. Internal to the core.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/mesh_distance.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

// Samples per block of the deviations' sums and lists: fixed blocks make the results independent
// of the number of threads.
inline constexpr size_t kDeviationSampleBlock = 4096;

// A fixed pseudo-random number for stratum j.
inline uint64_t stratum_hash(uint64_t j) {
  uint64_t h = (j + 1) * 0x9E3779B97F4A7C15ull;
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ull;
  h ^= h >> 32;
  return h;
}

// Whether sample s is its stratum's chosen one (every sample when the stride is 1).
inline bool stratum_chosen(size_t s, size_t stride) {
  return stride == 1 || s % stride == stratum_hash(s / stride) % stride;
}

// Calls f(s) for every chosen sample s in [begin, end), in increasing order. The chosen sample of
// each stratum is computed directly: testing every id with stratum_chosen (a hash and a 64-bit
// division each) took a third of the statistics' time on make_big.py's bone.
template <class F>
void for_each_chosen(size_t begin, size_t end, size_t stride, F&& f) {
  if (stride == 1) {
    for (size_t s = begin; s < end; ++s) f(s);
    return;
  }
  for (size_t j = begin / stride; j * stride < end; ++j) {
    const size_t s = j * stride + stratum_hash(j) % stride;
    if (s >= begin && s < end) f(s);
  }
}

// The stride that leaves about `limit` of n samples (1: all of them; limit 0: no limit).
inline size_t stratum_stride(size_t n, size_t limit) {
  return limit > 0 && n > limit ? (n + limit - 1) / limit : 1;
}

// The distances of the samples one direction measured, in sample order, with their sum and
// largest.
struct SampleDistances {
  std::vector<double> distances;
  double sum = 0;
  double max = 0;
};

// Measures samples [0, n) block by block in parallel: measure_block(begin, end, out) appends the
// distances of the samples of [begin, end) it measures to out, in order. The sum is taken within
// each block, then over the blocks in order: the same for any thread count.
template <class MeasureBlock>
SampleDistances measure_in_blocks(size_t n, MeasureBlock&& measure_block) {
  const size_t blocks = (n + kDeviationSampleBlock - 1) / kDeviationSampleBlock;
  std::vector<std::vector<double>> block_distances(blocks);
  std::vector<double> block_sum(blocks, 0.0), block_max(blocks, 0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      std::vector<double>& out = block_distances[b];
      measure_block(b * kDeviationSampleBlock, std::min(n, (b + 1) * kDeviationSampleBlock), out);
      for (double d : out) {
        block_sum[b] += d;
        block_max[b] = std::max(block_max[b], d);
      }
    }
  });
  SampleDistances all;
  size_t measured = 0;
  for (size_t b = 0; b < blocks; ++b) {
    all.sum += block_sum[b];
    all.max = std::max(all.max, block_max[b]);
    measured += block_distances[b].size();
  }
  all.distances.reserve(measured);
  for (std::vector<double>& d : block_distances) {
    all.distances.insert(all.distances.end(), d.begin(), d.end());
    d = {};
  }
  return all;
}

// Both directions pooled: the mean and the 95th percentile of their distances together, and
// the given Hausdorff distance. One addition of the two partial sums is commutative, which makes
// the mean exactly symmetric.
inline Deviation pooled_deviation(SampleDistances ab, SampleDistances ba, double hausdorff) {
  Deviation dev;
  dev.mean = (ab.sum + ba.sum) / double(ab.distances.size() + ba.distances.size());
  dev.hausdorff = hausdorff;
  ab.distances.insert(ab.distances.end(), ba.distances.begin(), ba.distances.end());
  ba.distances = {};
  dev.p95 = percentile(ab.distances, 0.95);
  return dev;
}

}  // namespace segmesh
