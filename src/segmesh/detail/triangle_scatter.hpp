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
struct TriangleChunks {
  std::vector<size_t> first{0};
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
