#include "segmesh/detail/dc_neighbourhood_keys.hpp"

#include <functional>
#include <numeric>

namespace segmesh::dc {

namespace {

// relevant_points for central differences ([0]) and Sobel ([1]).
constexpr std::array<std::array<uint64_t, 256>, 2> kRelevantPoints = [] {
  std::array<std::array<uint64_t, 256>, 2> out{};
  for (int sobel = 0; sobel < 2; ++sobel) {
    for (int cs = 0; cs < 256; ++cs) {
      uint64_t& mask = out[size_t(sobel)][size_t(cs)];
      for (int n = 0; n < 8; ++n) {
        const int x = 1 + (n & 1), y = 1 + (n >> 1 & 1), z = 1 + (n >> 2);
        mask |= key_bit(x, y, z);
        const int inside = cs >> n & 1;
        if ((cs >> (n ^ 1) & 1) == inside && (cs >> (n ^ 2) & 1) == inside &&
            (cs >> (n ^ 4) & 1) == inside) {
          continue;  // no cut edge at corner n
        }
        for (int d = 0; d < 27; ++d) {
          const int dx = d % 3 - 1, dy = d / 3 % 3 - 1, dz = d / 9 - 1;
          // Central differences read the six face neighbours, Sobel the whole 3 x 3 x 3.
          if (!sobel && dx * dx + dy * dy + dz * dz != 1) continue;
          mask |= key_bit(x + dx, y + dy, z + dz);
        }
      }
    }
  }
  return out;
}();

}  // namespace

const std::array<uint64_t, 256>& relevant_points(NormalMethod normals) {
  return kRelevantPoints[normals == NormalMethod::sobel];
}

uint64_t key_mask(NormalMethod normals) {
  const auto& points = relevant_points(normals);
  return std::reduce(points.begin(), points.end(), uint64_t{0}, std::bit_or<>());
}

}  // namespace segmesh::dc
