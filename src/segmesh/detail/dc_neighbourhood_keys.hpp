// Neighbourhood keys of Dual Contouring on a 0/1 field: the 4 x 4 x 4 grid points around a cell
// (offsets -1 .. 2 from its first corner) as one 64-bit word, bit n + 16 x for point (x, y, z),
// n = y + 4 z. A binary cell's sheet vertices depend on this neighbourhood alone (its corners and
// the points their gradients read), so the key indexes the solved vertices
// (dc_neighbourhood_cache.hpp); mirroring a key about the cell's centre mirrors its solution.
// WordColumns makes the keys of a word of cells from the sixteen rows of inside bits around
// them, four 16-bit columns per key.
#pragma once

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>

#include "segmesh/detail/inside_bits.hpp"
#include "segmesh/gradient.hpp"

namespace segmesh::dc {

// The bit of point (x, y, z) (each 0 .. 3, the cell's corners at 1 and 2) in a key.
constexpr uint64_t key_bit(int x, int y, int z) {
  return uint64_t{1} << (y + 4 * z + 16 * x);
}
// Whether that point is inside.
inline bool key_point(uint64_t key, int x, int y, int z) {
  return (key & key_bit(x, y, z)) != 0;
}

// The key of the 4 x 4 x 4 points mirrored about the cell's centre along the axes set in `axes`
// (bit a for axis a): coordinate c becomes 3 - c.
inline uint64_t mirror_key(uint64_t k, int axes) {
  if (axes & 1) {  // x: the four 16-bit columns in reverse order
    k = (k >> 32) | (k << 32);
    k = ((k >> 16) & 0x0000ffff0000ffffULL) | ((k & 0x0000ffff0000ffffULL) << 16);
  }
  if (axes & 2) {  // y: the four bits of every nibble in reverse order
    k = ((k >> 1) & 0x5555555555555555ULL) | ((k & 0x5555555555555555ULL) << 1);
    k = ((k >> 2) & 0x3333333333333333ULL) | ((k & 0x3333333333333333ULL) << 2);
  }
  if (axes & 4) {  // z: the four nibbles of every column in reverse order
    k = ((k >> 4) & 0x0f0f0f0f0f0f0f0fULL) | ((k & 0x0f0f0f0f0f0f0f0fULL) << 4);
    k = ((k >> 8) & 0x00ff00ff00ff00ffULL) | ((k & 0x00ff00ff00ff00ffULL) << 8);
  }
  return k;
}

// The smallest of a key's eight mirror images, and the mirror that gives it (the lowest such).
struct CanonicalKey {
  uint64_t key;
  int axes;
};
inline CanonicalKey canonical_key(uint64_t k) {
  CanonicalKey best{k, 0};
  for (int axes = 1; axes < 8; ++axes) {
    const uint64_t m = mirror_key(k, axes);
    if (m < best.key) best = {m, axes};
  }
  return best;
}

// The Marching Cubes case of the cell at the centre of a key.
inline int case_of_key(uint64_t key) {
  int cs = 0;
  for (int n = 0; n < 8; ++n)
    cs |= int(key_point(key, 1 + (n & 1), 1 + (n >> 1 & 1), 1 + (n >> 2))) << n;
  return cs;
}

// The points of a key its cell's vertices depend on, per case, for the normal operator: the
// cell's corners, and what the gradient reads around each corner with a cut edge (the gradients
// of the others are never used). Keys that differ elsewhere have the same solution, so they share
// a mirror class (dc_neighbourhood_cache.hpp).
const std::array<uint64_t, 256>& relevant_points(NormalMethod normals);

// The points any cell's gradients read, relevant_points over all cases: Sobel's 3 x 3 x 3 around
// each corner are all 64, central differences' six neighbours of each corner the 32 points with
// at most one coordinate at -1 or 2.
uint64_t key_mask(NormalMethod normals);

// The columns of the 16 rows around one row of cells (rows (j - 1 + y, k - 1 + z) at
// n = y + 4 z), 16 bits per grid point x (inside_bits.hpp's column_codes), for one word of cells
// and the points beyond it its cells read (x - 1 .. x + 2): code(b) for b = -1 .. 65 is column
// 64 w + b, and the four of cell b's neighbourhood are consecutive in memory, one 64-bit load.
class WordColumns {
 public:
  WordColumns(const uint64_t* const* rows, int64_t nx) : rows_(rows), nx_(nx) {}
  // The columns of word w, and those past its ends that the cells in `cells` read.
  void load(int64_t w, uint64_t cells) {
    // The columns of the word the cells read: b - 1 .. b + 2 for every cell b. Most words of a
    // surface have a few cells, and then these few columns are taken from the interleaved bytes
    // (column_bytes) rather than all 64.
    const uint64_t wanted = cells >> 1 | cells | cells << 1 | cells << 2;
    if (std::popcount(wanted) > kFewColumns) {
      column_codes(rows_, w, codes_ + 1);
    } else {
      column_bytes(rows_, w, bytes_);
      for (uint64_t m = wanted; m != 0; m &= m - 1) {
        const int b = std::countr_zero(m);
        codes_[b + 1] = column_code(bytes_, b);
      }
    }
    codes_[0] = (cells & 1) ? column(64 * w - 1) : 0;
    if (cells >> 62) codes_[65] = column(64 * w + 64), codes_[66] = column(64 * w + 65);
  }
  // Columns b - 1 .. b + 2 (b = 0 .. 63), 16 bits each, b - 1 lowest.
  uint64_t four(int b) const {
    uint64_t v;
    std::memcpy(&v, codes_ + b, sizeof v);
    return v;
  }

 private:
  uint16_t column(int64_t x) const {  // 0 outside the grid
    return x < 0 || x >= nx_ ? 0 : column_at(rows_, x);
  }
  static constexpr int kFewColumns = 24;
  const uint64_t* const* rows_;
  const int64_t nx_;
  ColumnBytes bytes_;
  uint16_t codes_[68] = {};  // code(b) at b + 1
};

// The key of cell b of the word `columns` holds, for a cell at least one point from the border:
// only the points the gradients read (key_mask), so cells that differ elsewhere share their
// entry. Never 0 for a non-trivial cell.
inline uint64_t neighbourhood_key(const WordColumns& columns, int b, uint64_t mask) {
  return columns.four(b) & mask;
}

}  // namespace segmesh::dc
