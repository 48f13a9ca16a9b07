// The sheets of a cell for Dual Contouring: which vertices a cell gets, and which of them each
// sign-changing edge's polygon uses.
//
// Plain Dual Contouring puts one vertex in every cell the surface crosses, even where the surface
// passes through the cell as separate sheets; the sheets then share that vertex and the mesh gets
// non-manifold vertices and edges. Here a cell gets one vertex per sheet, and the sheets are the
// pieces of the Marching Cubes surface of the cell (marching_cubes_table.hpp) — the same face rule,
// so neighbouring cells agree and the connectivity of the parts is the one Marching Cubes uses.
// The Dual Contouring mesh is then the dual of the Marching Cubes polygon mesh: a vertex per
// piece, a polygon per cut edge (the pieces around it, in order), an edge per face segment.
//
// The dual of a closed manifold polygon mesh is closed and manifold when no two of its polygons
// share more than one edge and every polygon is a disk. Two refinements make that true:
//   - a piece that holds both segments of one ambiguous face would share both with the piece of the
//     neighbouring cell across that face (a doubled edge in the dual); such a piece is cut in two by
//     a chord between its two halves, in every cell, so no neighbour can do the same;
//   - the 26-connectivity tube (an annulus, not a disk) is cut by three chords into three quads.
// A chord's ends then lie in two pieces of the cell, so the polygon of such a cut edge has five
// or six vertices instead of four. Built once per connectivity and checked when built.
#pragma once

#include <array>
#include <cstdint>

#include "segmesh/connectivity.hpp"

namespace segmesh {

inline constexpr int kDcMaxPieces = 8;

struct DcCase {
  uint8_t piece_count = 0;
  // The cut edges on each piece's boundary (their Hermite data make the piece's QEF).
  std::array<std::array<int8_t, 12>, kDcMaxPieces> piece_edges{};
  std::array<uint8_t, kDcMaxPieces> piece_edge_count{};
  // For each cut cell edge e along axis a: the pieces around e inside this cell, in order from the
  // cell face perpendicular to axis (a + 1) % 3 to the face perpendicular to axis (a + 2) % 3.
  std::array<std::array<int8_t, 3>, 12> around{};
  std::array<uint8_t, 12> around_count{};
};

struct DcTable {
  int connectivity = kDefaultConnectivity;
  std::array<DcCase, 256> cases;
};

// The table for connectivity 6, 18 or 26 (built once, thread-safe). Throws std::invalid_argument
// for any other connectivity and std::logic_error if a case violates the rules above.
const DcTable& dc_table(int connectivity);
DcTable build_dc_table(int connectivity);

}  // namespace segmesh
