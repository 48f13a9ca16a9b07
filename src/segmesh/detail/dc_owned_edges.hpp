// The cut edges a row of cells owns (dc_cell_rows.hpp), each with the four cells around it: what
// the polygon passes of Dual Contouring iterate over.
#pragma once

#include <array>
#include <bit>
#include <cstdint>

#include "segmesh/detail/dc_cell_rows.hpp"

namespace segmesh::dc {

// Which of a row's cut edges owned_edges visits: every one, only those next to a rare cell, or
// every one with each of its four cells checked to exist (throws std::logic_error at the first
// that does not: the field is not padded).
enum class Edges { all, next_to_rare, all_checked };

// Calls visit(axis, quadrant cells, inside at the edge's start) for every cut edge row (j, k)
// owns (of those `which` selects), in the order of the cells (x ascending) and, per cell, of its
// edges 3, 7 and 11. The quadrant cells are the four cells around the edge in polygon() order
// (kQuadrantDu / kQuadrantDv): their CellRefs, or with Edges::all, where no rare cell is near,
// their vertices (std::array<uint32_t, 4>: each holds one sheet). Unchecked, the cells of a row
// without rare cells are numbered by popcounts, which count_polygons has checked for the rows
// that need it.
template <Edges which, class Visit>
void owned_edges(const CellRows& rows, int64_t j, int64_t k, Visit&& visit) {
  const bool rare_only = which == Edges::next_to_rare;
  RowQuad q = rows.row_quad(j, k);
  const CellWord* own = rows.row_words(j, k);
  const CornerRows corner_rows = rows.corners(j, k);
  for (int64_t w = 0; w < rows.cw; ++w) {
    const uint64_t cells = own[w].cells;
    if (cells == 0) continue;
    rows.load_words(q, w);
    const CornerWords c = corner_rows.at(w);
    uint64_t e3 = c.cut3() & cells, e7 = c.cut7() & cells, e11 = c.cut11() & cells;
    if (rare_only) {
      auto right = [&](int r) { return (q.word[r].rare >> 1) | (q.next[r].rare << 63); };
      const uint64_t r0 = q.word[0].rare, r1 = q.word[1].rare, r2 = q.word[2].rare,
                     r3 = q.word[3].rare;
      e3 &= r0 | r1 | r2 | r3;
      e7 &= r0 | r2 | right(0) | right(2);
      e11 &= r0 | r1 | right(0) | right(1);
    }
    uint64_t rare = 0;
    for (int r = 0; r < 4; ++r) rare |= q.word[r].rare | (q.next[r].rare & 1);
    if constexpr (which == Edges::all) {
      if (rare == 0) {
        // No rare cell: every cell around the edges holds one sheet, numbered by a popcount
        // (count_polygons has checked that all four exist).
        auto id = [&](int r, int b) { return single_sheet(q, r, b).first_vertex; };
        using Ids = std::array<uint32_t, 4>;
        for (uint64_t m = e3 | e7 | e11; m != 0; m &= m - 1) {
          const int b = std::countr_zero(m);
          const uint64_t bit = uint64_t{1} << b;
          const uint32_t c0 = id(0, b);
          if (e3 & bit) visit(0, Ids{id(1, b), id(3, b), id(2, b), c0}, (c.v[6] & bit) != 0);
          if (e7 & bit) {
            visit(1, Ids{id(2, b), id(2, b + 1), id(0, b + 1), c0}, (c.v[5] & bit) != 0);
          }
          if (e11 & bit) {
            visit(2, Ids{id(0, b + 1), id(1, b + 1), id(1, b), c0}, (c.v[3] & bit) != 0);
          }
        }
        continue;
      }
    }
    for (uint64_t m = e3 | e7 | e11; m != 0; m &= m - 1) {
      const int b = std::countr_zero(m);
      const uint64_t bit = uint64_t{1} << b;
      if (e3 & bit) {
        visit(0,
              std::array<CellRef, 4>{rows.cell(q, 1, w, b), rows.cell(q, 3, w, b),
                                     rows.cell(q, 2, w, b), rows.cell(q, 0, w, b)},
              (c.v[6] & bit) != 0);
      }
      if (e7 & bit) {
        visit(1,
              std::array<CellRef, 4>{rows.cell(q, 2, w, b), rows.cell(q, 2, w, b + 1),
                                     rows.cell(q, 0, w, b + 1), rows.cell(q, 0, w, b)},
              (c.v[5] & bit) != 0);
      }
      if (e11 & bit) {
        visit(2,
              std::array<CellRef, 4>{rows.cell(q, 0, w, b + 1), rows.cell(q, 1, w, b + 1),
                                     rows.cell(q, 1, w, b), rows.cell(q, 0, w, b)},
              (c.v[3] & bit) != 0);
      }
    }
  }
}

}  // namespace segmesh::dc
