// Neighbourhood keys of the binary cells of a label map's materials, for multi-label Dual
// Contouring (multi_label_dual_contouring.hpp): a cell whose corners hold two materials is solved
// as single-label Dual Contouring of the winner's indicator, keyed by the winner's 4 x 4 x 4
// neighbourhood (dc_neighbourhood_keys.hpp), of which only the 32 points central differences read
// matter (key_mask). Those lie in twelve rows (y, z) of the neighbourhood: all but the four with
// both y and z outside the cell.
//
// Two ways to read them, the same keys bit for bit:
//   - MaterialBits: every part's inside bits on its own bounding box (grown by two points, so that
//     every neighbourhood of a cell of the part is inside it), set from the runs; a key is twelve
//     word reads. Memory one bit per point of every part's box, so it is only made while the boxes
//     together stay within a bound (MaterialBits::fits); a binary cell's neighbourhood lies in its
//     winner's box grown by two points, so no key reads outside its part's bits.
//   - RowWindow: a cursor into one row's runs (material_rows.hpp), read four points at a time at
//     x ascending; twelve of them for a row of cells. No memory, a few branches per row.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/detail/material_rows.hpp"

namespace segmesh::dc {

// The rows (y, z) of a key that central differences read, as the shift y + 4 z of their bits.
inline constexpr std::array<int, 12> kKeyRowShift = {1, 2, 4, 5, 6, 7, 8, 9, 10, 11, 13, 14};

// Bits 0 .. 3 of `bits` moved to bits 0, 16, 32 and 48 (a key's x = 0 .. 3 of one row): the four
// partial products of the multiplication never overlap.
inline uint64_t spread_row(unsigned bits) {
  return (uint64_t{bits} * 0x0000200040008001ULL) & 0x0001000100010001ULL;
}

// The materials of one row of grid points, read four points at a time at x ascending: a cursor
// into the row's runs, which only moves forward.
class RowWindow {
 public:
  RowWindow() = default;
  explicit RowWindow(std::span<const MaterialRun> runs)
      : at_(runs.data()), end_(runs.data() + runs.size()) {}
  // Bit x set where point x0 + x (x = 0 .. 3) holds material w; x0 never decreases.
  unsigned equal4(int64_t x0, uint32_t w) {
    while (at_ != end_ && at_->x_end <= x0) ++at_;
    if (at_ == end_ || at_->x_begin >= x0 + 4) return 0;  // the four points between runs
    if (at_->x_begin <= x0 && at_->x_end >= x0 + 4) return at_->material == w ? 0xfu : 0u;
    unsigned bits = 0;
    for (const MaterialRun* r = at_; r != end_ && r->x_begin < x0 + 4; ++r) {
      if (r->material != w) continue;
      const int64_t b = std::max<int64_t>(r->x_begin - x0, 0);
      const int64_t e = std::min<int64_t>(r->x_end - x0, 4);
      bits |= (1u << e) - (1u << b);
    }
    return bits;
  }

 private:
  const MaterialRun* at_ = nullptr;
  const MaterialRun* end_ = nullptr;
};

// The twelve RowWindows of the neighbourhoods of row j of slab k of cells, in kKeyRowShift order.
std::array<RowWindow, 12> key_windows(const MaterialRows& rows, int64_t j, int64_t k);

// The key of cell i of the row `windows` were made for, in material w's indicator, before
// key_mask; cells at i ascending.
inline uint64_t window_key(std::array<RowWindow, 12>& windows, int64_t i, uint32_t w) {
  uint64_t key = 0;
  for (size_t n = 0; n < 12; ++n) key |= spread_row(windows[n].equal4(i - 1, w)) << kKeyRowShift[n];
  return key;
}

// A part's bounding box: first and last point, inclusive.
using PartBox = std::array<std::array<int64_t, 3>, 2>;

// The boxes of components.components[parts[n]] in the local indices of MaterialRows(grid,
// components, parts) (whose box is theirs with a one-point margin).
std::vector<PartBox> part_boxes(const Components& components, std::span<const size_t> parts);

// Every part's inside bits on its bounding box grown by two points on every side, in the local
// indices of MaterialRows; material m is part m - 1.
class MaterialBits {
 public:
  // Whether the grown boxes of parts whose boxes are `boxes` (first, last; inclusive, local
  // indices) hold at most four points per point of the common box `dims`: then the bits take at
  // most half a byte per point of it. The phantom's, the pelvic fracture maps' and the
  // TotalSegmentator maps' take 0.7 to 3.2 points; a map of random label noise, whose thousands of
  // small components have large boxes, takes a hundred and reads its runs instead.
  static bool fits(std::span<const PartBox> boxes, const std::array<int64_t, 3>& dims);
  MaterialBits(const MaterialRows& rows, std::span<const PartBox> boxes);

  // The key of cell (i, j, k) in material w's indicator, before key_mask; w must hold a corner of
  // the cell.
  uint64_t key(uint32_t w, int64_t i, int64_t j, int64_t k) const {
    const Part& p = parts_[w - 1];
    const int64_t x = i - 1 - p.origin[0];
    const size_t word = size_t(x >> 6);
    const unsigned shift = unsigned(x & 63);
    const uint64_t* base = bits_.data() + p.first_word + word;
    const int64_t y0 = j - 1 - p.origin[1], z0 = k - 1 - p.origin[2];
    uint64_t key = 0;
    for (size_t n = 0; n < 12; ++n) {
      const int y = kKeyRowShift[n] & 3, z = kKeyRowShift[n] >> 2;
      const uint64_t* row = base + size_t((z0 + z) * p.dims[1] + (y0 + y)) * p.words;
      const unsigned four = unsigned((row[0] >> shift | (row[1] << 1) << (63 - shift)) & 0xf);
      key |= spread_row(four) << kKeyRowShift[n];
    }
    return key;
  }

 private:
  struct Part {
    std::array<int64_t, 3> origin;  // local index of the grown box's first point
    std::array<int64_t, 3> dims;    // the grown box
    size_t words;                   // per row (one more than the box needs: reads take two)
    size_t first_word;
  };
  std::vector<Part> parts_;
  std::vector<uint64_t> bits_;
};

}  // namespace segmesh::dc
