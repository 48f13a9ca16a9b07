// Inside bits: which grid points of a field are inside, packed 64 to a word along x, row by row.
//
// Dual Contouring (dual_contouring.cpp, dc_cell_rows.hpp) works on these instead of the field: the Marching Cubes
// case of a cell is two bits from each of four rows, the cells that hold surface are a few word
// operations per 64 cells (a cell is non-trivial when its eight corners are not all equal), and
// the 4 x 4 x 4 neighbourhood that decides a binary cell's vertex is four 16-bit columns of the
// sixteen rows around the cell's row (column_codes; column_bytes and column_code for a few). A
// part's bits come straight from its runs, so no byte mask of its bounding box is ever built: one
// bit per grid point instead of one byte.
//
// Every row ends with at least one zero word, so reading the word after the one holding x never
// leaves the row.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "segmesh/component_field.hpp"
#include "segmesh/components.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

struct InsideBits {
  std::array<int64_t, 3> dims{};
  int64_t words = 0;            // per row: ceil(nx / 64) + 1
  std::vector<uint64_t> bits;   // row (j, k) starts at (k * ny + j) * words

  const uint64_t* row(int64_t j, int64_t k) const {
    return bits.data() + static_cast<size_t>((k * dims[1] + j) * words);
  }
  bool at(int64_t i, int64_t j, int64_t k) const {
    return (row(j, k)[i >> 6] >> (i & 63) & 1) != 0;
  }
};

// Sets bits [lo, hi) of a row (lo < hi): a run of voxels.
inline void set_bit_run(uint64_t* row, int64_t lo, int64_t hi) {
  const int64_t wl = lo >> 6, wh = (hi - 1) >> 6;
  const uint64_t first = ~uint64_t{0} << (lo & 63);
  const uint64_t last = ~uint64_t{0} >> (63 - ((hi - 1) & 63));
  if (wl == wh) {
    row[wl] |= first & last;
    return;
  }
  row[wl] |= first;
  for (int64_t w = wl + 1; w < wh; ++w) row[w] = ~uint64_t{0};
  row[wh] |= last;
}

// Bits x and x + 1 of a row (x + 1 may be the first bit of the next word).
inline unsigned bit_pair(const uint64_t* row, int64_t x) {
  const int64_t w = x >> 6;
  const unsigned s = static_cast<unsigned>(x & 63);
  return static_cast<unsigned>(((row[w] >> s) | ((row[w + 1] << 1) << (63 - s))) & 3u);
}

// Word w of a row moved down by one bit: its bit b is the row's bit 64 w + b + 1.
inline uint64_t shifted_word(const uint64_t* row, int64_t w) {
  return (row[w] >> 1) | (row[w + 1] << 63);
}

// Column x of 16 rows, one bit at a time: bit n is bit x of rows[n].
inline uint16_t column_at(const uint64_t* const* rows, int64_t x) {
  unsigned code = 0;
  for (int n = 0; n < 16; ++n) code |= unsigned(rows[n][x >> 6] >> (x & 63) & 1) << n;
  return static_cast<uint16_t>(code);
}

// The 64 columns of word w of 16 rows: bit n of codes[b] is bit 64 w + b of rows[n]. (A bit
// matrix transpose; with SSE2 a byte transpose and 64 movemasks instead of 1024 bit extractions.)
void column_codes(const uint64_t* const* rows, int64_t w, uint16_t* codes);

// The first half of column_codes, for words where only a few columns are wanted: word w of 16
// rows with its bytes interleaved, byte n of lane m being byte m of rows[n][w], so that bit i of
// lane m's sixteen bytes is column 8 m + i (column_code). The 64 movemasks of the second half
// cost more than this half.
struct ColumnBytes {
  alignas(16) uint8_t lane[8][16];
};
void column_bytes(const uint64_t* const* rows, int64_t w, ColumnBytes& out);

// Column b (0 .. 63) of a word column_bytes interleaved: codes[b] of column_codes.
inline uint16_t column_code(const ColumnBytes& c, int b) {
#if defined(__SSE2__)
  const __m128i v = _mm_load_si128(reinterpret_cast<const __m128i*>(c.lane[b >> 3]));
  // movemask takes bit 7 of each byte; a 16-bit shift moves bit i there in both bytes.
  return static_cast<uint16_t>(_mm_movemask_epi8(_mm_sll_epi16(v, _mm_cvtsi32_si128(7 - (b & 7)))));
#else
  unsigned code = 0;
  for (int n = 0; n < 16; ++n) code |= unsigned(c.lane[b >> 3][n] >> (b & 7) & 1) << n;
  return static_cast<uint16_t>(code);
#endif
}

// The grid points where value >= iso (integers against ceil(iso), floating point in double, NaN
// outside: row_trim.hpp's InsideTest). Parallel over rows.
template <class T>
InsideBits inside_bits(const Volume<T>& field, double iso, Progress& progress = null_progress());

// The points of one component on its bounding box grown by `margin` (component_grid's domain),
// set run by run.
InsideBits inside_bits(const Components& components, const Component& component,
                       FieldMargin margin = kDefaultFieldMargin);

extern template InsideBits inside_bits(const Volume<uint8_t>&, double, Progress&);
extern template InsideBits inside_bits(const Volume<int32_t>&, double, Progress&);
extern template InsideBits inside_bits(const Volume<float>&, double, Progress&);

}  // namespace segmesh
