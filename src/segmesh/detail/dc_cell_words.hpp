// Dual Contouring's cells 64 at a time: the word-level code over the inside bits
// (inside_bits.hpp) of the four rows of grid points at a row of cells' corners.
//
// A row of cells (j, k) lies between rows of points (j, k), (j + 1, k), (j, k + 1) and
// (j + 1, k + 1). For one word of 64 cells, the eight corner words say, bit by bit, which corner
// of each cell is inside; from them a handful of word operations give the cells that hold surface,
// those that may be rare (not exactly one sheet), the cut edges each cell owns, and any one cell's
// Marching Cubes case.
#pragma once

#include <cstdint>

#include "segmesh/detail/inside_bits.hpp"

namespace segmesh::dc {

// One word of a row of cells: the non-trivial cells among 64 consecutive ones, and the rare ones
// among those (not exactly one sheet, or several sheets around one edge): only next to a rare
// cell can a polygon have more than four vertices, and only after one in its row are the cells
// numbered past extra sheets.
struct CellWord {
  uint64_t cells = 0;
  uint64_t rare = 0;
};

// The eight corner words of one word of cells between rows a = (j, k), b = (j + 1, k),
// c = (j, k + 1), d = (j + 1, k + 1) of inside bits: bit x of v[2 r] is the left corner of cell x
// on row r, bit x of v[2 r + 1] its right corner; so the Marching Cubes case of cell x takes bit x
// of v[n] as its corner n (marching_cubes_table.hpp numbering).
struct CornerWords {
  uint64_t v[8];
  CornerWords() = default;
  CornerWords(const uint64_t* a, const uint64_t* b, const uint64_t* c, const uint64_t* d,
              int64_t w) {
    const uint64_t* rows[4] = {a, b, c, d};
    for (int r = 0; r < 4; ++r) {
      v[2 * r] = rows[r][w];
      v[2 * r + 1] = shifted_word(rows[r], w);
    }
  }
  // The cells whose corners are not all inside or all outside.
  uint64_t nontrivial() const {
    uint64_t any = 0, all = ~uint64_t{0};
    for (uint64_t x : v) any |= x, all &= x;
    return any & ~all;
  }
  // Every cell of the word in case cs.
  static CornerWords of_case(int cs) {
    CornerWords c;
    for (int n = 0; n < 8; ++n) c.v[n] = (cs >> n & 1) ? ~uint64_t{0} : 0;
    return c;
  }
  int case_of(int b) const {
    int cs = 0;
    for (int n = 0; n < 8; ++n) cs |= int(v[n] >> b & 1) << n;
    return cs;
  }
  // The cells that may hold other than one sheet: an ambiguous face (its diagonal corners equal,
  // adjacent ones not), or two body-opposite corners that differ from the other six. CellRows
  // checks once that every rare case of its table is among these.
  uint64_t maybe_rare() const {
    static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                         {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    uint64_t maybe = 0;
    for (const auto& f : kFaces)
      maybe |= ~(v[f[0]] ^ v[f[2]]) & ~(v[f[1]] ^ v[f[3]]) & (v[f[0]] ^ v[f[1]]);
    for (int p = 0; p < 4; ++p) {  // corners p and 7 - p
      const int o = p == 0 ? 1 : 0;  // one of the other six
      uint64_t alone = ~(v[p] ^ v[7 - p]) & (v[p] ^ v[o]);
      for (int n = 0; n < 8; ++n) {
        if (n != p && n != 7 - p) alone &= ~(v[n] ^ v[o]);
      }
      maybe |= alone;
    }
    return maybe;
  }
  // The edges every cell owns (its edges 3, 7 and 11, at its corner 7): cut when corner 7
  // differs from corner 6, 5 or 3.
  uint64_t cut3() const { return v[6] ^ v[7]; }
  uint64_t cut7() const { return v[5] ^ v[7]; }
  uint64_t cut11() const { return v[3] ^ v[7]; }
};

// The four rows of inside bits at the corners of one row of cells, word by word.
struct CornerRows {
  const uint64_t* row[4];
  CornerWords at(int64_t w) const { return {row[0], row[1], row[2], row[3], w}; }
};

}  // namespace segmesh::dc
