// The Marching Cubes case table: for each of the 256 inside/outside patterns of a cell's eight
// corners, the triangles (as triples of cut cell edges) that separate inside from outside.
//
// The table is not typed in; it is derived from one rule, so it is complete and consistent by
// construction (build_mc_table in the .cpp, checked by the tests):
//   1. On each cell face, the cut edges are joined by segments. A face with four cut edges is
//      ambiguous (two inside corners on one diagonal, two outside on the other); the rule decides
//      it from the face's own corners only, so the two cells sharing a face always agree and the
//      surface has no cracks.
//   2. The segments form closed cycles on the cell's boundary; each cycle is spanned by a disk of
//      triangles, wound counter-clockwise seen from outside (the side of the lower values).
//   3. Triangulations never use a diagonal between two vertices on a common face (such an edge
//      could be shared with the neighbouring cell and carry four triangles); among the allowed
//      ones the table takes the one with the best radii ratios for vertices at edge midpoints,
//      which is where every vertex of a binary label map lies.
//
// The rule is chosen to match the voxel connectivity the parts use, so one connected component
// of voxels gives one connected surface (plus one shell per enclosed cavity):
//   connectivity 6:  ambiguous faces separate the inside corners            (inside 6,  outside 18)
//   connectivity 18: ambiguous faces join the inside corners                (inside 18, outside 6)
//   connectivity 26: as 18, and two inside corners on a body diagonal with
//                    all six others outside are joined by a tube through
//                    the cell instead of two separate corner triangles      (inside 26, outside 6)
// These are the classic well-behaved digital-topology pairs; every result is a closed,
// edge-manifold, consistently wound surface.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "segmesh/connectivity.hpp"

namespace segmesh {

// Corner c of a cell sits at offset (c & 1, (c >> 1) & 1, (c >> 2) & 1).
inline constexpr std::array<std::array<int, 3>, 8> kMcCornerOffset{{
    {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}}};

// Edge e runs along axis e / 4 from corner kMcEdgeCorner[e][0] to kMcEdgeCorner[e][1]; its other
// two coordinates are the two bits of e % 4 (for axis x: y + 2z, for y: x + 2z, for z: x + 2y).
inline constexpr std::array<std::array<int, 2>, 12> kMcEdgeCorner{{
    {0, 1}, {2, 3}, {4, 5}, {6, 7},    // x edges
    {0, 2}, {1, 3}, {4, 6}, {5, 7},    // y edges
    {0, 4}, {1, 5}, {2, 6}, {3, 7}}};  // z edges

struct McTable {
  int connectivity = kDefaultConnectivity;
  // Triangles of case c are triangles[first[c]] .. triangles[first[c + 1] - 1]; the case index
  // has bit k set when corner k is inside.
  std::array<uint16_t, 257> first{};
  std::vector<std::array<uint8_t, 3>> triangles;  // cell edge indices, counter-clockwise

  int triangle_count(int c) const { return first[c + 1] - first[c]; }
};

// The surface of one case before triangulation: closed cycles of cut edges on the cell boundary,
// each counter-clockwise seen from outside; `tube` when the two cycles bound one tube (the
// 26-connectivity body-diagonal case). Dual Contouring builds its per-sheet vertices from this.
struct McCaseTopology {
  std::vector<std::vector<int>> cycles;
  bool tube = false;
};
McCaseTopology mc_case_topology(int cs, int connectivity);

// The face (2 * axis + side) that holds both cell edges, or -1 when they share none.
int mc_shared_face(int e0, int e1);

// The table for connectivity 6, 18 or 26 (built once, thread-safe). Throws std::invalid_argument
// for any other connectivity.
const McTable& mc_table(int connectivity);

// Builds a table from the rule above (exposed for the tests).
McTable build_mc_table(int connectivity);

}  // namespace segmesh
