#include "segmesh_io/detail/byte_order.hpp"

#include <cstdint>

namespace segmesh {

void swap_bytes_inplace(void* data, size_t count, size_t size) {
  auto* bytes = static_cast<unsigned char*>(data);
  const auto swap_each = [&](auto word) {
    using W = decltype(word);
    for (size_t i = 0; i < count; ++i) {
      W w;
      std::memcpy(&w, bytes + i * sizeof(W), sizeof(W));
      if constexpr (sizeof(W) == 2) w = __builtin_bswap16(w);
      if constexpr (sizeof(W) == 4) w = __builtin_bswap32(w);
      if constexpr (sizeof(W) == 8) w = __builtin_bswap64(w);
      std::memcpy(bytes + i * sizeof(W), &w, sizeof(W));
    }
  };
  switch (size) {
    case 1:
      return;
    case 2:
      return swap_each(uint16_t{});
    case 4:
      return swap_each(uint32_t{});
    case 8:
      return swap_each(uint64_t{});
    default:
      for (size_t i = 0; i < count; ++i) std::reverse(bytes + i * size, bytes + (i + 1) * size);
  }
}

}  // namespace segmesh
