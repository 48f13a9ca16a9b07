// A point's exact coordinates as a hash key: the bit patterns of its three floats, so a map keyed
// by them never merges two points anyone could tell apart, with -0 folded onto +0 (a mirrored
// export still matches). For welding corners by position (the STL reader) and for finding the
// vertex at a position (the report's contact gaps).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "segmesh/vec3.hpp"

namespace segmesh {

struct PositionKey {
  uint32_t x = 0, y = 0, z = 0;
  bool operator==(const PositionKey&) const = default;
};

inline PositionKey position_key(Vec3f p) {
  auto bits = [](float v) {
    if (v == 0.0f) v = 0.0f;
    uint32_t b;
    std::memcpy(&b, &v, 4);
    return b;
  };
  return {bits(p.x), bits(p.y), bits(p.z)};
}

struct PositionKeyHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = k.x * 0x9E3779B97F4A7C15ull;
    h ^= (k.y + 0x7F4A7C15ull + (h << 6) + (h >> 2)) * 0xC2B2AE3D27D4EB4Full;
    h ^= (k.z + 0x165667B19E3779F9ull + (h << 6) + (h >> 2)) * 0x94D049BB133111EBull;
    return static_cast<size_t>(h ^ (h >> 31));
  }
};

}  // namespace segmesh
