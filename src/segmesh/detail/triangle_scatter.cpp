#include "segmesh/detail/triangle_scatter.hpp"

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

ChunkRanges chunk_ranges(const std::vector<uint32_t>& idx, size_t count) {
  const size_t nt = idx.size() / 3;
  ChunkRanges chunks;
  chunks.first.resize(count + 1);
  for (size_t c = 0; c <= count; ++c) chunks.first[c] = nt * c / count;
  chunks.ids.resize(count);
  tbb::parallel_for(size_t{0}, count, [&](size_t c) {
    chunks.ids[c] = vertex_range(idx, chunks.first[c], chunks.first[c + 1]);
  });
  return chunks;
}

void merge_neighbour_chunks(ChunkRanges& chunks) {
  std::vector<size_t> first{0};
  std::vector<std::pair<uint32_t, uint32_t>> ids;
  for (size_t c = 0; c < chunks.count(); c += 2) {
    const size_t d = std::min(c + 1, chunks.count() - 1);
    ids.push_back({std::min(chunks.ids[c].first, chunks.ids[d].first),
                   std::max(chunks.ids[c].second, chunks.ids[d].second)});
    first.push_back(chunks.first[d + 1]);
  }
  chunks.first = std::move(first);
  chunks.ids = std::move(ids);
}

TriangleChunks triangle_chunks(const std::vector<uint32_t>& idx, size_t min_triangles) {
  const size_t nt = idx.size() / 3;
  TriangleChunks chunks;
  const size_t count = std::min(kMaxChunks, nt / std::max<size_t>(1, min_triangles));
  if (count < 3) {  // two chunks would run one after the other anyway
    chunks.first.push_back(nt);
    return chunks;
  }
  ChunkRanges ranges = chunk_ranges(idx, count);
  // Chunks c and c + 2 disjoint for every c makes every two of one parity disjoint (the ranges
  // then increase along each parity). Otherwise neighbouring chunks merge, halving the count.
  auto disjoint = [&] {
    for (size_t c = 0; c + 2 < ranges.count(); ++c)
      if (ranges.ids[c].second >= ranges.ids[c + 2].first) return false;
    return true;
  };
  while (ranges.count() >= 3 && !disjoint()) merge_neighbour_chunks(ranges);
  if (ranges.count() >= 3) {
    chunks.first = std::move(ranges.first);
    chunks.ids = std::move(ranges.ids);
  } else {
    chunks.first.push_back(nt);
  }
  return chunks;
}

FinishPlan finish_plan(const TriangleChunks& chunks, size_t n) {
  FinishPlan plan;
  // Each odd chunk's id range; each even chunk's less the odd ranges (along each parity the
  // ranges increase and are disjoint, so a walk over the odd ones finds the gaps). Ids at or past
  // n are cut off.
  plan.first.push_back(0);
  const size_t count = chunks.ids.size();  // 0 for a mesh of one chunk: everything is the rest
  for (size_t c = 0; c < count; ++c) {
    const size_t lo = chunks.ids[c].first,
                 end = std::min<size_t>(n, size_t{chunks.ids[c].second} + 1);
    auto give = [&](size_t a, size_t b) {
      if (a < b) plan.ranges.push_back({a, b});
    };
    if (c % 2 == 1) {
      give(lo, end);
    } else {
      size_t a = lo;
      for (size_t d = 1; d < count && a < end; d += 2) {
        const size_t olo = chunks.ids[d].first, oend = size_t{chunks.ids[d].second} + 1;
        if (oend <= a) continue;
        if (olo >= end) break;
        give(a, std::max(a, olo));
        a = std::max(a, oend);
      }
      give(a, end);
    }
    plan.first.push_back(plan.ranges.size());
  }
  // The rest: the gaps between the ranges given out.
  std::vector<std::pair<size_t, size_t>> covered = plan.ranges;
  std::sort(covered.begin(), covered.end());
  size_t next = 0;
  for (const auto& [a, b] : covered) {
    if (next < a) plan.ranges.push_back({next, a});
    next = std::max(next, b);
  }
  if (next < n) plan.ranges.push_back({next, n});
  return plan;
}

}  // namespace segmesh
