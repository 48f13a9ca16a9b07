#include "segmesh/detail/mesh_adjacency.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <limits>
#include <tuple>

#include "segmesh/first_touch.hpp"
#include "segmesh/detail/triangle_scatter.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace segmesh {

namespace {

// Below this many triangles the rows are built by one serial pass (parts are built in parallel
// anyway); above it, in chunks of at least kMinChunkTriangles.
constexpr size_t kParallelTriangles = 1 << 16;
constexpr size_t kMinChunkTriangles = 1 << 15;
constexpr size_t kMaxChunks = 64;
constexpr size_t kVertexBlock = 1 << 14;

struct Chunk {
  size_t first = 0, last = 0;  // triangles [first, last)
  uint32_t lo = std::numeric_limits<uint32_t>::max(), hi = 0;  // vertex ids touched
  size_t base = 0;                                               // its counters in the scratch
  size_t range() const { return lo <= hi ? size_t{hi} - lo + 1 : 0; }
};

std::vector<Chunk> make_chunks(const std::vector<uint32_t>& idx, size_t nv) {
  const size_t nt = idx.size() / 3;
  size_t count = 1;
  if (nt >= kParallelTriangles) {
    const size_t threads = static_cast<size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    count = std::clamp<size_t>(4 * threads, 1, kMaxChunks);
    count = std::min(count, std::max<size_t>(1, nt / kMinChunkTriangles));
  }
  ChunkRanges ranges = chunk_ranges(idx, count);
  // Scattered vertex ids: merge neighbouring chunks until the counters fit in about 2 per vertex.
  auto total = [&] {
    size_t sum = 0;
    for (const auto& [lo, hi] : ranges.ids) sum += size_t{hi} - lo + 1;
    return sum;
  };
  while (ranges.count() > 1 && total() > 2 * nv + 4096) merge_neighbour_chunks(ranges);
  std::vector<Chunk> chunks(ranges.count());
  size_t base = 0;
  for (size_t c = 0; c < chunks.size(); ++c) {
    chunks[c].first = ranges.first[c];
    chunks[c].last = ranges.first[c + 1];
    std::tie(chunks[c].lo, chunks[c].hi) = ranges.ids[c];
    chunks[c].base = base;
    base += chunks[c].range();
  }
  return chunks;
}

}  // namespace

bool mesh_rows_fit_32(size_t index_count) {
  return index_count < size_t{std::numeric_limits<uint32_t>::max()};
}

template <class Index>
VertexRows<Index> vertex_corners(const std::vector<uint32_t>& idx, size_t nv) {
  VertexRows<Index> rows;
  if (idx.empty() || nv == 0) {
    rows.offsets.assign(nv + 1, 0);
    return rows;
  }
  // Made resident and zeroed in parallel: the first touch of fresh pages is the costly part
  // (first_touch.hpp).
  rows.offsets.resize(nv + 1);
  first_touch(rows.offsets.data(), rows.offsets.size() * sizeof(Index));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv + 1, kVertexBlock),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::fill(rows.offsets.begin() + ptrdiff_t(r.begin()),
                                rows.offsets.begin() + ptrdiff_t(r.end()), Index{0});
                    });

  std::vector<Chunk> chunks = make_chunks(idx, nv);
  std::vector<Index> counts;
  resize_zeroed(counts, chunks.back().base + chunks.back().range());

  // 1. Corners per vertex, per chunk.
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t c) {
    const Chunk& ch = chunks[c];
    Index* cnt = counts.data() + ch.base;
    for (size_t h = 3 * ch.first; h != 3 * ch.last; ++h) ++cnt[idx[h] - ch.lo];
  });

  // 2. Per vertex, each chunk's counter becomes its first slot in the row (chunks in order); the
  // degrees go to offsets[v], then an exclusive scan over fixed vertex blocks.
  const size_t blocks = (nv + kVertexBlock - 1) / kVertexBlock;
  std::vector<Index> block_sum(blocks + 1, 0);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    const size_t v0 = b * kVertexBlock, v1 = std::min(nv, v0 + kVertexBlock);
    for (const Chunk& ch : chunks) {
      const size_t lo = std::max<size_t>(v0, ch.lo), hi = std::min<size_t>(v1, size_t{ch.hi} + 1);
      if (ch.range() == 0 || lo >= hi) continue;
      Index* cnt = counts.data() + ch.base;
      for (size_t v = lo; v < hi; ++v) {
        const Index n = cnt[v - ch.lo];
        cnt[v - ch.lo] = rows.offsets[v];
        rows.offsets[v] += n;
      }
    }
    Index sum = 0;
    for (size_t v = v0; v < v1; ++v) sum += rows.offsets[v];
    block_sum[b + 1] = sum;
  });
  for (size_t b = 0; b < blocks; ++b) block_sum[b + 1] += block_sum[b];
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    const size_t v0 = b * kVertexBlock, v1 = std::min(nv, v0 + kVertexBlock);
    Index start = block_sum[b];
    for (size_t v = v0; v < v1; ++v) {
      const Index n = rows.offsets[v];
      rows.offsets[v] = start;
      start += n;
    }
  });
  rows.offsets[nv] = block_sum[blocks];
  // Each chunk's first slot in every row it touches, as an absolute position.
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t c) {
    const Chunk& ch = chunks[c];
    Index* cnt = counts.data() + ch.base;
    for (size_t k = 0; k < ch.range(); ++k) cnt[k] += rows.offsets[ch.lo + k];
  });

  // 3. Fill: each chunk writes its corners, in triangle order, from its first slots on.
  rows.entries.resize(idx.size());
  first_touch(rows.entries.data(), rows.entries.size() * sizeof(Index));
  tbb::parallel_for(size_t{0}, chunks.size(), [&](size_t c) {
    const Chunk& ch = chunks[c];
    Index* cnt = counts.data() + ch.base;
    Index* entries = rows.entries.data();
    for (size_t h = 3 * ch.first; h != 3 * ch.last; ++h) entries[cnt[idx[h] - ch.lo]++] = static_cast<Index>(h);
  });
  return rows;
}

namespace {

// The ring of one vertex from its corners' (next, previous) pairs; false unless they form one
// closed fan (header). d > 0. The general case: O(d^2).
template <class Index>
bool fan_ring(uint32_t v, const uint32_t* next, const uint32_t* prev, size_t d, Index* ring) {
  for (size_t k = 0; k < d; ++k)
    if (next[k] == v || prev[k] == v) return false;
  size_t cur = 0;
  ring[0] = next[0];
  for (size_t m = 1; m <= d; ++m) {
    // The corner whose next is the current corner's previous: exactly one.
    const uint32_t want = prev[cur];
    size_t found = d;
    for (size_t j = 0; j < d; ++j) {
      if (next[j] == want) {
        if (found != d) return false;
        found = j;
      }
    }
    if (found == d) return false;
    if (m == d) return found == 0;  // back at the start after visiting every corner once
    if (found == 0) return false;   // closed early: more than one fan
    ring[m] = next[found];
    cur = found;
  }
  return false;
}

// Bit k set where a[k] == x, k < 8.
inline unsigned match8(const uint32_t* a, uint32_t x) {
#if defined(__SSE2__)
  const __m128i key = _mm_set1_epi32(static_cast<int>(x));
  const __m128i lo = _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a)), key);
  const __m128i hi = _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(a + 4)), key);
  return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(lo))) |
         static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(hi))) << 4;
#else
  unsigned m = 0;
  for (unsigned k = 0; k < 8; ++k) m |= static_cast<unsigned>(a[k] == x) << k;
  return m;
#endif
}

// fan_ring for 1 <= d <= 8 (nearly every vertex), with next[d .. 8) padded with v: one vector
// compare per corner finds its successor, then the walk follows the successors. Every corner
// must have exactly one successor, and the walk from corner 0 must return to it after exactly d
// steps; then the successors form one cycle through all corners (a shorter cycle, or one that
// misses corner 0, would never lead back to it at step d).
template <class Index>
bool small_fan_ring(uint32_t v, const uint32_t* next, const uint32_t* prev, size_t d, Index* ring) {
  const unsigned used = (1u << d) - 1;
  if ((match8(next, v) & used) != 0) return false;
  uint8_t succ[8];
  for (size_t j = 0; j < d; ++j) {
    const unsigned m = match8(next, prev[j]) & used;
    // m must have exactly one bit (no std::popcount: without -mpopcnt it is a library call).
    if (prev[j] == v || m == 0 || (m & (m - 1)) != 0) return false;
    succ[j] = static_cast<uint8_t>(std::countr_zero(m));
  }
  size_t cur = 0;
  ring[0] = next[0];
  for (size_t m = 1; m < d; ++m) {
    cur = succ[cur];
    if (cur == 0) return false;
    ring[m] = next[cur];
  }
  return succ[cur] == 0;
}

}  // namespace

template <class Index>
bool corners_to_rings(const std::vector<uint32_t>& idx, VertexRows<Index>& rows) {
  const size_t nv = rows.offsets.size() - 1;
  std::atomic<bool> ok{true};
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, nv, 4096), [&](const tbb::blocked_range<size_t>& r) {
        if (!ok.load(std::memory_order_relaxed)) return;
        constexpr size_t kLocal = 32;
        uint32_t next_local[kLocal], prev_local[kLocal];
        std::vector<uint32_t> next_heap, prev_heap;
        for (size_t v = r.begin(); v != r.end(); ++v) {
          const size_t d = rows.size(v);
          if (d == 0) continue;
          uint32_t* next = next_local;
          uint32_t* prev = prev_local;
          if (d > kLocal) {
            next_heap.resize(d);
            prev_heap.resize(d);
            next = next_heap.data();
            prev = prev_heap.data();
          }
          Index* row = rows.entries.data() + rows.offsets[v];
          for (size_t k = 0; k < d; ++k) {
            next[k] = corner_next(idx, row[k]);
            prev[k] = corner_prev(idx, row[k]);
          }
          bool fan;
          if (d <= 8) {
            for (size_t k = d; k < 8; ++k) next[k] = static_cast<uint32_t>(v);
            fan = small_fan_ring(static_cast<uint32_t>(v), next, prev, d, row);
          } else {
            fan = fan_ring(static_cast<uint32_t>(v), next, prev, d, row);
          }
          if (!fan) {
            ok.store(false, std::memory_order_relaxed);
            return;
          }
        }
      });
  return ok.load();
}

template VertexRows<uint32_t> vertex_corners<uint32_t>(const std::vector<uint32_t>&, size_t);
template VertexRows<uint64_t> vertex_corners<uint64_t>(const std::vector<uint32_t>&, size_t);
template bool corners_to_rings<uint32_t>(const std::vector<uint32_t>&, VertexRows<uint32_t>&);
template bool corners_to_rings<uint64_t>(const std::vector<uint32_t>&, VertexRows<uint64_t>&);

}  // namespace segmesh
