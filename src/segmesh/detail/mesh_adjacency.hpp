// Vertex-to-triangle adjacency for the mesh measures (mesh_measures.cpp): compressed rows of the
// triangle corners at each vertex, and, for closed oriented manifold meshes (what Marching Cubes
// and Dual Contouring produce), the ring of each vertex's neighbours in fan order, which holds
// the neighbour set and the triangles at once.
//
// Building the rows is a transpose of the index array (corner -> vertex), done in parallel
// without atomics and without sorting: the triangles are cut into a few chunks; each chunk counts
// its corners per vertex in a private array that spans only the vertex ids it touches (narrow for
// spatially ordered meshes: Marching Cubes numbers vertices and triangles plane by plane), the
// counts become each chunk's first slot in every row (chunks in order), and each chunk fills its
// slots in triangle order. Every row therefore lists its corners in increasing order, whatever
// the number of chunks or threads. When the chunks' vertex ranges overlap too much (a mesh with
// scattered vertex ids), adjacent chunks are merged, down to one serial pass, so the scratch
// memory stays below about two counters per vertex.
//
// Cost: three reads of the index array and one scattered write of the rows; memory: the rows
// (4 bytes per vertex plus 4 per corner: 12 per triangle) and the counters while building.
// (Smoothing used these rows until it moved to sums over the triangles, triangle_scatter.hpp:
// building them cost more than the four sweeps of HC x2; docs/PERFORMANCE.md.)
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace segmesh {

// A std::vector whose resize leaves new elements of trivial types uninitialised (no zero fill
// before a pass that writes every element anyway).
template <class T>
struct UninitializedAllocator : std::allocator<T> {
  using std::allocator<T>::allocator;
  template <class U>
  struct rebind {
    using other = UninitializedAllocator<U>;
  };
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
};
template <class T>
using UninitializedVector = std::vector<T, UninitializedAllocator<T>>;

// Row i is entries[offsets[i] .. offsets[i + 1]). Index is uint32_t when 3 x triangles fits in 32
// bits (every mesh in practice), uint64_t otherwise; mesh_rows_fit_32 says which.
template <class Index>
struct VertexRows {
  UninitializedVector<Index> offsets;  // vertex count + 1
  UninitializedVector<Index> entries;

  size_t size(size_t i) const { return offsets[i + 1] - offsets[i]; }
  const Index* begin(size_t i) const { return entries.data() + offsets[i]; }
  const Index* end(size_t i) const { return entries.data() + offsets[i + 1]; }
};

bool mesh_rows_fit_32(size_t index_count);

// The corners at each vertex: entries are corner ids 3 t + k (corner k of triangle t), each row in
// increasing order. Precondition: every index is below vertex_count.
template <class Index>
VertexRows<Index> vertex_corners(const std::vector<uint32_t>& indices, size_t vertex_count);

// Turns corner rows into neighbour rings when every vertex with a triangle is the apex of exactly
// one closed fan: its triangles (v, n_k, p_k) chain up as p_k = n_{k+1}, once around, with no
// repeated neighbour and no corner equal to v. Then the mesh is closed, edge-manifold and
// consistently oriented, row v becomes its neighbours n_0, n_1, ... in that order, starting at
// the next corner of v's first triangle, and the triangles at v are (v, n_k, n_{k+1 mod d}),
// counter-clockwise as in the mesh. Returns false otherwise, leaving `rows` in an unspecified
// state (rebuild with vertex_corners). Parallel; the result does not depend on the thread count.
template <class Index>
bool corners_to_rings(const std::vector<uint32_t>& indices, VertexRows<Index>& rows);

// The other two corners of corner id c: (next, previous) in the triangle's winding.
inline uint32_t corner_next(const std::vector<uint32_t>& indices, uint64_t c) {
  return indices[c % 3 == 2 ? c - 2 : c + 1];
}
inline uint32_t corner_prev(const std::vector<uint32_t>& indices, uint64_t c) {
  return indices[c % 3 == 0 ? c + 2 : c - 1];
}

}  // namespace segmesh
