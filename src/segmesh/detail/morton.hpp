// Morton (Z-order) keys of 21-bit grid coordinates: the octree of Dual Contouring's
// simplification (dual_contouring_simplify.cpp) and the spatial order of the distance trees
// (ordered_triangle_tree.cpp). Internal to the core.
#pragma once

#include <array>
#include <cstdint>

namespace segmesh {

inline uint64_t spread_bits(uint64_t v) {  // 21 bits to every third bit
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

inline uint64_t compact_bits(uint64_t v) {
  v &= 0x1249249249249249ULL;
  v = (v ^ (v >> 2)) & 0x10c30c30c30c30c3ULL;
  v = (v ^ (v >> 4)) & 0x100f00f00f00f00fULL;
  v = (v ^ (v >> 8)) & 0x1f0000ff0000ffULL;
  v = (v ^ (v >> 16)) & 0x1f00000000ffffULL;
  v = (v ^ (v >> 32)) & 0x1fffffULL;
  return v;
}

inline uint64_t morton(int64_t x, int64_t y, int64_t z) {
  return spread_bits(uint64_t(x)) | spread_bits(uint64_t(y)) << 1 | spread_bits(uint64_t(z)) << 2;
}

inline std::array<int64_t, 3> unmorton(uint64_t key) {
  return {int64_t(compact_bits(key)), int64_t(compact_bits(key >> 1)),
          int64_t(compact_bits(key >> 2))};
}

}  // namespace segmesh
