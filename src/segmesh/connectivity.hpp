// Voxel connectivity: which voxels of one label count as joined (6: across faces; 18: also across
// edges; 26: also across corners) and, consistently, which surface sheets the extractors keep
// apart. Every options struct, table and front end takes its default and its check from here.
#pragma once

#include <string_view>

namespace segmesh {

inline constexpr int kDefaultConnectivity = 26;

constexpr bool is_connectivity(int connectivity) {
  return connectivity == 6 || connectivity == 18 || connectivity == 26;
}

// Throws std::invalid_argument("<who>: connectivity must be 6, 18 or 26 (got N)") unless
// is_connectivity.
void require_connectivity(int connectivity, std::string_view who);

// The index of a valid connectivity among 6, 18, 26 (0, 1, 2), for per-connectivity tables;
// require_connectivity first.
inline int connectivity_index(int connectivity) {
  require_connectivity(connectivity, "connectivity_index");
  return connectivity == 6 ? 0 : connectivity == 18 ? 1 : 2;
}

}  // namespace segmesh
