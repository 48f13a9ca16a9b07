// The rows of cells Dual Contouring works in, and what its first passes count in them.
//
// Cells live in rows (j, k), index k * cy + j, and within a row in words of 64 cells
// (dc_cell_words.hpp). Vertex ids follow the rows, the cells of a row in x order and the sheets
// of a cell in order; every cut edge's polygon is emitted by the cell that has the edge as its
// edge 3, 7 or 11 (the cell at the edge's lower corner on the two other axes), so the triangles
// follow the rows too. A cell's first vertex is its row's first plus the sheets before it, a
// popcount within its word (plus the extra sheets of rare cells before it), so no list of cells
// is ever stored.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "segmesh/detail/dc_cell_words.hpp"
#include "segmesh/detail/dc_polygons.hpp"
#include "segmesh/detail/dual_contouring_simplify.hpp"
#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/detail/inside_bits.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh::dc {

// One row's count as the row arrays keep it (32-bit like the ids they count to).
inline uint32_t count32(uint64_t n) { return mesh_id_count(n, "dual contouring"); }

// The four rows of cells around the edges row (j, k) owns — (j, k), (j + 1, k), (j, k + 1),
// (j + 1, k + 1), as quadrant rows 0 .. 3 — seen at one word: the cells' words and the first
// vertex of each row's word.
struct RowQuad {
  int64_t j, k;
  bool exists[4];
  uint32_t row_first[4];  // first vertex of each row
  uint32_t first[4];      // first vertex of word w of each row (when it or word w + 1 has cells)
  CellWord word[4], next[4];  // words w and w + 1 (zero where absent)
};

// The cells before cell b (0 .. 64) of a word.
inline uint64_t below(int b) { return b < 64 ? (uint64_t{1} << b) - 1 : ~uint64_t{0}; }

// Cell b of quadrant row r's word when no rare cell precedes it there and it is not rare: its
// first vertex is a popcount.
inline CellRef single_sheet(const RowQuad& q, int r, int b) {
  return {kOneSheet, q.first[r] + static_cast<uint32_t>(std::popcount(q.word[r].cells & below(b)))};
}

struct CellRows {
  // Checks once that CornerWords::maybe_rare finds every rare case of the table (throws
  // std::logic_error otherwise).
  CellRows(const InsideBits& bits, const DcTable& table);

  const InsideBits& bits;
  const DcTable& table;
  const int64_t nx, ny, nz;  // grid points
  const int64_t cx, cy, cz;  // cells
  const int64_t cw;          // words of cells per row
  std::array<bool, 256> rare{};  // per case: not exactly one sheet, or several around one edge

  // Filled by count_cells and count_polygons, made first ids by prefix_sums.
  std::vector<CellWord> words;              // per row of cells, cw words
  std::unique_ptr<uint32_t[]> word_first;   // per word with cells: the row's sheets before it
  std::vector<uint8_t> row_rare;            // per row of cells: any rare cell
  std::vector<uint8_t> row_short;           // per row of cells: a cut edge without its four cells
  std::vector<uint32_t> vertex_first;       // per row: its first sheet vertex (rows() + 1)
  std::vector<uint32_t> triangle_first;     // per row: its first triangle
  std::vector<uint32_t> extra_first;        // per row: its first centroid vertex (after the sheets)

  int64_t rows() const { return cy * cz; }
  size_t row_index(int64_t j, int64_t k) const { return static_cast<size_t>(k * cy + j); }
  const CellWord* row_words(int64_t j, int64_t k) const {
    return words.data() + row_index(j, k) * size_t(cw);
  }
  CornerRows corners(int64_t j, int64_t k) const {
    return {{bits.row(j, k), bits.row(j + 1, k), bits.row(j, k + 1), bits.row(j + 1, k + 1)}};
  }
  // The cells of word w that exist (x < cx).
  uint64_t valid(int64_t w) const {
    const int64_t n = cx - 64 * w;
    return n >= 64 ? ~uint64_t{0} : (uint64_t{1} << n) - 1;
  }
  int case_at(int64_t x, int64_t j, int64_t k) const {
    return int(bit_pair(bits.row(j, k), x) | bit_pair(bits.row(j + 1, k), x) << 2 |
               bit_pair(bits.row(j, k + 1), x) << 4 | bit_pair(bits.row(j + 1, k + 1), x) << 6);
  }
  int pieces(int cs) const { return table.cases[static_cast<size_t>(cs)].piece_count; }

  // The sheets of the cells of row (j, k)'s word w in `mask`.
  uint32_t sheets_in(int64_t j, int64_t k, int64_t w, uint64_t mask) const {
    const CellWord& word = row_words(j, k)[w];
    uint32_t n = static_cast<uint32_t>(std::popcount(word.cells & mask));
    for (uint64_t m = word.rare & mask; m != 0; m &= m - 1) {
      n += static_cast<uint32_t>(pieces(case_at(64 * w + std::countr_zero(m), j, k))) - 1;
    }
    return n;
  }

  RowQuad row_quad(int64_t j, int64_t k) const {
    RowQuad q{j, k, {}, {}, {}, {}, {}};
    for (int r = 0; r < 4; ++r) {
      const int64_t jr = j + (r & 1), kr = k + (r >> 1);
      q.exists[r] = jr < cy && kr < cz;
      q.row_first[r] = q.exists[r] ? vertex_first[row_index(jr, kr)] : 0;
    }
    return q;
  }
  void load_words(RowQuad& q, int64_t w) const {
    for (int r = 0; r < 4; ++r) {
      if (!q.exists[r]) continue;
      const size_t at = row_index(q.j + (r & 1), q.k + (r >> 1)) * size_t(cw) + size_t(w);
      q.word[r] = words[at];
      q.next[r] = w + 1 < cw ? words[at + 1] : CellWord{};
      // An empty word's first vertex is the next word's (word_first is set only for words with
      // cells).
      q.first[r] = q.row_first[r] + (q.word[r].cells   ? word_first[at]
                                     : q.next[r].cells ? word_first[at + 1]
                                                       : 0);
    }
  }

  // Cell b (0 .. 64: 64 is bit 0 of the next word) of word w of quadrant row r, as polygon()
  // needs it; throws when absent (a cut edge without its four cells: the field is not padded).
  CellRef cell(const RowQuad& q, int r, int64_t w, int b) const {
    const int64_t jr = q.j + (r & 1), kr = q.k + (r >> 1);
    const bool present = q.exists[r] && (b < 64 ? q.word[r].cells >> b & 1 : q.next[r].cells & 1);
    if (!present) {
      throw std::logic_error(
          "dual contouring: the field is inside at its border (a cut edge without its four "
          "cells); pad it with a layer of background");
    }
    CellRef c = q.word[r].rare & below(b)
                    ? CellRef{kOneSheet, q.first[r] + sheets_in(jr, kr, w, below(b))}
                    : single_sheet(q, r, b);
    if (b < 64 ? q.word[r].rare >> b & 1 : q.next[r].rare & 1) c.cs = case_at(64 * w + b, jr, kr);
    return c;
  }

  // Totals, after prefix_sums.
  uint64_t sheets() const { return vertex_first.back(); }
  uint64_t vertices() const { return sheets() + extra_first.back(); }
  uint64_t triangles() const { return triangle_first.back(); }
};

// Pass 1, in parallel over rows: the cell words, each row's sheets (into vertex_first[r + 1]),
// two triangles per cut edge it owns (into triangle_first[r + 1], corrected by count_polygons),
// whether it has rare cells, and whether it owns a cut edge without its four cells (at the row's
// or the grid's end).
void count_cells(CellRows& rows, Progress& progress);

// The rows' counts into their first ids: vertex_first[r] is row r's first sheet vertex,
// triangle_first[r] its first triangle, extra_first[r] its first centroid vertex (after the
// sheets); entry rows() is the total. Throws where the sheets and centroid vertices, or the
// triangles, are more than 32-bit ids can number.
void prefix_sums(CellRows& rows);

// The cells with sheets and their first vertex (for the simplification), in vertex order.
std::vector<SurfaceCell> surface_cells(const CellRows& rows);

}  // namespace segmesh::dc
