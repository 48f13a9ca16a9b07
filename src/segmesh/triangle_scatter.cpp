#include "segmesh/triangle_scatter.hpp"

#include <algorithm>
#include <limits>

namespace segmesh {

namespace {
constexpr size_t kMaxChunks = 64;
}  // namespace

std::pair<uint32_t, uint32_t> vertex_range(const std::vector<uint32_t>& idx, size_t first,
                                           size_t last) {
  // Signed comparisons of the ids with the top bit flipped (the same order as unsigned ones):
  // compilers vectorise these with baseline SSE2, which has no unsigned 32-bit minimum.
  constexpr uint32_t kFlip = 0x80000000u;
  int32_t lo = std::numeric_limits<int32_t>::max(), hi = std::numeric_limits<int32_t>::min();
  for (size_t h = 3 * first; h != 3 * last; ++h) {
    const auto v = static_cast<int32_t>(idx[h] ^ kFlip);
    lo = v < lo ? v : lo;
    hi = v > hi ? v : hi;
  }
  return {static_cast<uint32_t>(lo) ^ kFlip, static_cast<uint32_t>(hi) ^ kFlip};
}

TriangleChunks triangle_chunks(const std::vector<uint32_t>& idx, size_t min_triangles) {
  const size_t nt = idx.size() / 3;
  TriangleChunks chunks;
  size_t count = std::min(kMaxChunks, nt / std::max<size_t>(1, min_triangles));
  if (count < 3) {  // two chunks would run one after the other anyway
    chunks.first.push_back(nt);
    return chunks;
  }
  std::vector<size_t> first(count + 1);
  for (size_t c = 0; c <= count; ++c) first[c] = nt * c / count;
  std::vector<std::pair<uint32_t, uint32_t>> range(count);
  tbb::parallel_for(size_t{0}, count,
                    [&](size_t c) { range[c] = vertex_range(idx, first[c], first[c + 1]); });
  // Chunks c and c + 2 disjoint for every c makes every two of one parity disjoint (the ranges
  // then increase along each parity). Otherwise neighbouring chunks merge, halving the count.
  auto disjoint = [&] {
    for (size_t c = 0; c + 2 < range.size(); ++c)
      if (range[c].second >= range[c + 2].first) return false;
    return true;
  };
  while (range.size() >= 3 && !disjoint()) {
    std::vector<size_t> f{0};
    std::vector<std::pair<uint32_t, uint32_t>> r;
    for (size_t c = 0; c < range.size(); c += 2) {
      const size_t d = std::min(c + 1, range.size() - 1);
      r.push_back(
          {std::min(range[c].first, range[d].first), std::max(range[c].second, range[d].second)});
      f.push_back(first[d + 1]);
    }
    first = std::move(f);
    range = std::move(r);
  }
  if (range.size() < 3) first = {0, nt};
  chunks.first = std::move(first);
  return chunks;
}

}  // namespace segmesh
