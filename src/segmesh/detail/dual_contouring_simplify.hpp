// Adaptive simplification of a Dual Contouring mesh over an octree (Ju, Losasso, Schaefer and
// Warren 2002, section 4): the cells are grouped into an octree bottom-up, and the 2x2x2 children
// of a node collapse into one vertex when
//   - every child crossed by the surface holds a single sheet and has itself collapsed,
//   - the node's own corner signs give a single sheet (one disk),
//   - no sign change hides inside the node: the sign at the midpoint of each of its edges, the
//     centre of each face and its centre equals the sign of at least one corner of that edge,
//     face or node (the topology-safety test of the paper),
//   - the merged QEF of the children, solved with the same singular-value cut-off, stays within
//     the tolerance (its RMS distance to the children's tangent planes, in mm).
// The mesh's vertices are then replaced by their highest collapsed ancestor: a quad whose corners
// share a node becomes a triangle, one inside a node disappears — exactly the polygons the octree
// recursion (edgeProc over minimal edges) would emit. Flat regions get fewer, larger triangles;
// the topology does not change. Octree nodes are kept sparse (Morton keys of nodes the surface
// crosses only).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "segmesh/dual_contouring.hpp"
#include "segmesh/grid.hpp"
#include "segmesh/detail/qef.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

// A cell the surface crosses: its position, Marching Cubes case and first sheet vertex.
struct SurfaceCell {
  int32_t i = 0, j = 0, k = 0;
  uint8_t cs = 0;
  uint32_t first_vertex = 0;
};

// What simplification needs to know about the uniform Dual Contouring result.
struct DcCells {
  std::array<int64_t, 3> cells{};             // cells per axis (grid points - 1)
  std::vector<SurfaceCell> surface;           // every cell with at least one sheet
  const std::vector<Qef>* qefs = nullptr;     // per sheet vertex, in its cell's local frame (mm)
  std::function<bool(int64_t, int64_t, int64_t)> inside;  // sign at a grid point
};

TriMesh simplify_dual_contour(TriMesh mesh, const DcCells& cells, const Grid& grid,
                              const DcOptions& options);

}  // namespace segmesh
