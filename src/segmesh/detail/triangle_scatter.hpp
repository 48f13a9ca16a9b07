// Per-vertex sums over a mesh's triangles ("scatter": every triangle adds its terms to its three
// corners), in parallel, without atomics or locks, and identical for any thread count.
//
// The triangles are cut into chunks of consecutive triangles fixed by the mesh alone, never by
// the threads, and visited in two passes: the even chunks side by side, then the odd ones. The
// chunks are made large enough that any two of the same parity touch disjoint ranges of vertex
// ids, so within a pass no two tasks write the same vertex, and every vertex receives its terms
// in one fixed order (its even chunk's before its odd chunk's, each chunk's in triangle order).
// Meshes whose triangles and vertices are numbered in the same spatial order (Marching Cubes and
// Dual Contouring number both plane by plane) touch narrow id ranges per chunk and keep many
// chunks; a mesh with scattered ids is merged down to one chunk, visited by one thread.
//
// Cost: one read of the index array to find the chunks' vertex ranges (chunk_ranges, also used by
// mesh_adjacency.cpp), then nothing per pass but the tasks.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace segmesh {

// The smallest and largest vertex id of triangles [first, last) (first < last).
std::pair<uint32_t, uint32_t> vertex_range(const std::vector<uint32_t>& indices, size_t first,
                                           size_t last);

// Triangles cut into chunks of consecutive triangles, with the vertex ids each touches: the
// mechanism under triangle_chunks (below) and mesh_adjacency.cpp's transpose, which differ only in
// when they merge neighbouring chunks.
struct ChunkRanges {
  std::vector<size_t> first;                       // chunk c: triangles [first[c], first[c + 1])
  std::vector<std::pair<uint32_t, uint32_t>> ids;  // chunk c's smallest and largest vertex id
  size_t count() const { return ids.size(); }
};

// `count` chunks of equal size (1 <= count <= the triangle count), their ids found in parallel.
ChunkRanges chunk_ranges(const std::vector<uint32_t>& indices, size_t count);

// Chunks 2c and 2c + 1 become chunk c (a last odd chunk stays as it is): half as many.
void merge_neighbour_chunks(ChunkRanges& chunks);

// Chunk c holds triangles [first[c], first[c + 1]); chunks c and c + 2k touch disjoint vertex ids.
// With three chunks or more, ids[c] is chunk c's smallest and largest vertex id (empty otherwise).
struct TriangleChunks {
  std::vector<size_t> first{0};
  std::vector<std::pair<uint32_t, uint32_t>> ids;
  size_t count() const { return first.size() - 1; }
};

// Chunks of at least min_triangles (but one chunk for fewer than twice that), at most 64, for any
// index array (ids need not be below any vertex count here).
TriangleChunks triangle_chunks(const std::vector<uint32_t>& indices,
                               size_t min_triangles = size_t{1} << 14);

// body(first, last) for every chunk's triangles: the even chunks in parallel, then the odd ones.
// body may add to per-vertex arrays at its triangles' corners without synchronisation.
template <class Body>
void scatter_triangles(const TriangleChunks& chunks, Body&& body) {
  for (size_t parity = 0; parity < 2; ++parity) {
    const size_t n = (chunks.count() + 1 - parity) / 2;
    if (n == 1) {
      body(chunks.first[parity], chunks.first[parity + 1]);
      continue;
    }
    tbb::parallel_for(size_t{0}, n, [&](size_t h) {
      const size_t c = 2 * h + parity;
      body(chunks.first[c], chunks.first[c + 1]);
    });
  }
}

// Which vertices of [0, n) are complete after which chunk of a scatter, for a vertex pass fused
// into it (scatter_then_finish). A vertex in an odd chunk's id range is touched by no other odd
// chunk and by even chunks only, which run before: it is complete after its odd chunk. A vertex in
// an even chunk's range and in no odd chunk's is complete after that even chunk (no other chunk
// touches it). The others (ids no chunk's range holds; every vertex of a mesh with one chunk) are
// the rest, finished after the whole scatter. Each vertex is in exactly one range.
struct FinishPlan {
  std::vector<size_t> first;  // chunk c finishes ranges [first[c], first[c + 1]); the rest after
  std::vector<std::pair<size_t, size_t>> ranges;  // half-open vertex id ranges
};
FinishPlan finish_plan(const TriangleChunks& chunks, size_t n);

// The scatter of scatter_triangles with a vertex pass fused into it: finish(v0, v1) for every
// range of `plan` (finish_plan(chunks, n)) in the task of the chunk after which its vertices are
// complete, right after that chunk's body (its vertices still in cache), and for the rest after
// the scatter, in parallel. finish may read a vertex's sums and write anything of that vertex
// (also what body reads at other vertices: no chunk that runs later or alongside touches it).
// Each vertex gets the same sums, in the same order, as with scatter_triangles then a pass.
template <class Body, class Finish>
void scatter_then_finish(const TriangleChunks& chunks, const FinishPlan& plan, Body&& body,
                         Finish&& finish) {
  auto run = [&](size_t c) {
    body(chunks.first[c], chunks.first[c + 1]);
    if (c + 1 < plan.first.size())
      for (size_t r = plan.first[c]; r != plan.first[c + 1]; ++r)
        finish(plan.ranges[r].first, plan.ranges[r].second);
  };
  for (size_t parity = 0; parity < 2; ++parity) {
    const size_t n = (chunks.count() + 1 - parity) / 2;
    if (n == 1) {
      run(parity);
      continue;
    }
    tbb::parallel_for(size_t{0}, n, [&](size_t h) { run(2 * h + parity); });
  }
  constexpr size_t kGrain = 4096;
  for (size_t r = plan.first.empty() ? 0 : plan.first.back(); r < plan.ranges.size(); ++r) {
    const auto [v0, v1] = plan.ranges[r];
    tbb::parallel_for(tbb::blocked_range<size_t>(v0, v1, kGrain),
                      [&](const tbb::blocked_range<size_t>& b) { finish(b.begin(), b.end()); });
  }
}

// f(t) for every triangle t in [first, last), in an order fixed by the range: blocks of 64 K
// triangles, each walked as four interleaved quarters (t, t + q, t + 2 q, t + 3 q, t + 1, ...).
// Consecutive triangles of a mesh share vertices, so adding their terms one after the other makes
// each vertex's additions wait on the previous one's store; triangles a quarter block apart
// rarely share one, so the four streams overlap (docs/PERFORMANCE.md has the measurement).
template <class F>
void for_each_interleaved(size_t first, size_t last, F&& f) {
  constexpr size_t kBlock = size_t{1} << 16;
  for (size_t s = first; s < last; s += kBlock) {
    const size_t e = s + kBlock < last ? s + kBlock : last;
    const size_t q = (e - s) / 4;
    for (size_t k = s; k < s + q; ++k) {
      f(k);
      f(k + q);
      f(k + 2 * q);
      f(k + 3 * q);
    }
    for (size_t k = s + 4 * q; k < e; ++k) f(k);
  }
}

}  // namespace segmesh
