// Dual Contouring's sheet vertices: the Hermite data of a cell's cut edges (crossing and unit
// normal) and the QEF vertex of each sheet (qef.hpp), kept inside the cell.
//
// A cell's Hermite data come from the field itself (cell_hermite, any field) or, for a 0/1 field,
// from its neighbourhood key (key_hermite, bit for bit the same). Everything is relative to the
// cell's first corner, before the grid's rotation, so a solution can be reused by every cell with
// the same neighbourhood (dc_neighbourhood_cache.hpp).
#pragma once

#include <array>
#include <cstdint>

#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/detail/edge_intersection.hpp"
#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/qef.hpp"
#include "segmesh/dual_contouring.hpp"
#include "segmesh/grid.hpp"

namespace segmesh::dc {

// What a sheet vertex depends on besides its cell: the cell's shape and rotation, the options
// that shape a QEF vertex, the case table, and whether vertex normals are made.
struct SheetSolve {
  const Grid& grid;
  const DcOptions& options;
  const DcTable& table;
  bool normals;
  bool cubic = false;  // cell_hermite takes cubic_edge_crossing (a grey-value field, DcHermite::cubic)
  // How far a single sheet's vertex may leave its cell, as a fraction of the cell: a grey-value
  // field's options.cell_reach, or a 0/1 field's -kDcCellMargin (it stays inside).
  double reach = -kDcCellMargin;

  int pieces(int cs) const { return table.cases[static_cast<size_t>(cs)].piece_count; }
};

// The Hermite data of a cell's cut edges, relative to the cell: crossing in millimetres from the
// cell's first corner (before the grid's rotation), unit outward normal in the same frame.
struct CellHermite {
  std::array<Vec3d, 12> point;
  std::array<Vec3d, 12> normal;
};

// The sheet vertices of one cell, relative to it: index-space offset from the cell's first corner
// and the sum of the crossings' unit normals in the cell's frame (world_normal turns it into the
// vertex normal), per piece.
struct CellVertices {
  std::array<Vec3d, kDcMaxPieces> offset;
  std::array<Vec3d, kDcMaxPieces> normal_sum;
};

// Edge e's crossing c as Hermite data of cell (i, j, k) with case cs.
inline void store_crossing(const SheetSolve& s, CellHermite& h, int e, int cs,
                           const EdgeCrossing& c, int64_t i, int64_t j, int64_t k) {
  const auto& sp = s.grid.spacing;
  const int axis = e / 4;
  h.point[e] = {(c.index_point.x - double(i)) * sp[0], (c.index_point.y - double(j)) * sp[1],
                (c.index_point.z - double(k)) * sp[2]};
  Vec3d n{-c.index_gradient.x / sp[0], -c.index_gradient.y / sp[1], -c.index_gradient.z / sp[2]};
  double len = norm(n);
  if (!(len > 0)) {  // no gradient: the edge itself, pointing from inside to outside
    n = {double(axis == 0), double(axis == 1), double(axis == 2)};
    if (!(cs >> kMcEdgeCorner[e][0] & 1)) n = -1.0 * n;
    len = 1;
  }
  h.normal[e] = (1.0 / len) * n;
}

// The Hermite data of the cut edges of cell (i, j, k) of field f with case cs.
template <class F>
CellHermite cell_hermite(const SheetSolve& s, const Volume<F>& f, int64_t i, int64_t j,
                         int64_t k, int cs) {
  CellHermite h;
  for (int e = 0; e < 12; ++e) {
    const int c0 = kMcEdgeCorner[e][0];
    if ((cs >> c0 & 1) == (cs >> kMcEdgeCorner[e][1] & 1)) continue;
    const int64_t gi = i + (c0 & 1), gj = j + (c0 >> 1 & 1), gk = k + (c0 >> 2);
    const EdgeCrossing c =
        s.cubic ? cubic_edge_crossing(f, gi, gj, gk, e / 4, s.options.iso, s.options.normals)
                : edge_crossing(f, gi, gj, gk, e / 4, s.options.iso, s.options.normals);
    store_crossing(s, h, e, cs, c, i, j, k);
  }
  return h;
}

// The Hermite data of the cut edges of the cell at the centre of a neighbourhood key: what
// cell_hermite gives for cell (1, 1, 1) of a 4 x 4 x 4 field holding the key, bit for bit (on a
// 0/1 field the crossings are edge midpoints and the gradients multiples of 1/32, all exact),
// from the key's bits: each corner's gradient once instead of once per cut edge at it.
CellHermite key_hermite(const SheetSolve& s, uint64_t key, int cs);

// The QEF vertices of every sheet of a cell with case cs and Hermite data h; the QEFs into
// `qefs` when given (simplification).
CellVertices solve_sheets(const SheetSolve& s, const CellHermite& h, int cs, Qef* qefs);

// The sheets of a binary cell from its neighbourhood key, which gives exactly what the whole
// field gives, as every gradient of the cell's corners reads only those points.
inline CellVertices solve_key(const SheetSolve& s, uint64_t key, int cs, Qef* qefs) {
  return solve_sheets(s, key_hermite(s, key, cs), cs, qefs);
}

// The world unit normal of a sheet whose crossings' unit normals add up to normal_sum.
Vec3f world_normal(const Grid& grid, Vec3d normal_sum);

}  // namespace segmesh::dc
