// The stratified samples of the deviation statistics (moved_mesh_deviation.hpp,
// mesh_deviation in mesh_distance.hpp): above a limit, the mean and the 95th percentile are taken
// over one sample in every stratum of `stride` consecutive sample ids (neighbours on the surface),
// at a fixed pseudo-random place in it, the same for any thread count. Internal to the core.
#pragma once

#include <cstddef>
#include <cstdint>

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

}  // namespace segmesh
