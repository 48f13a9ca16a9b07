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
// Cost: one read of the index array to find the chunks' vertex ranges (vertex_range, also used by
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

}  // namespace segmesh
