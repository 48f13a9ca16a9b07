#include "segmesh/detail/dc_material_keys.hpp"

#include <tbb/parallel_for.h>

#include <limits>

#include "segmesh/detail/inside_bits.hpp"
#include "segmesh/first_touch.hpp"

namespace segmesh::dc {

namespace {

// The grown box of a part whose box is `box` (first, last; inclusive).
std::array<int64_t, 3> grown_dims(const PartBox& box) {
  return {box[1][0] - box[0][0] + 5, box[1][1] - box[0][1] + 5, box[1][2] - box[0][2] + 5};
}

}  // namespace

std::vector<PartBox> part_boxes(const Components& components, std::span<const size_t> parts) {
  std::array<int64_t, 3> origin;
  origin.fill(std::numeric_limits<int64_t>::max());
  for (size_t p : parts)
    for (size_t a = 0; a < 3; ++a)
      origin[a] = std::min(origin[a], components.components[p].first[a] - 1);
  std::vector<PartBox> boxes(parts.size());
  for (size_t n = 0; n < parts.size(); ++n)
    for (size_t a = 0; a < 3; ++a) {
      boxes[n][0][a] = components.components[parts[n]].first[a] - origin[a];
      boxes[n][1][a] = components.components[parts[n]].last[a] - origin[a];
    }
  return boxes;
}

std::array<RowWindow, 12> key_windows(const MaterialRows& rows, int64_t j, int64_t k) {
  std::array<RowWindow, 12> windows;
  for (size_t n = 0; n < 12; ++n) {
    const int y = kKeyRowShift[n] & 3, z = kKeyRowShift[n] >> 2;
    windows[n] = RowWindow(rows.row(j - 1 + y, k - 1 + z));
  }
  return windows;
}

bool MaterialBits::fits(std::span<const PartBox> boxes, const std::array<int64_t, 3>& dims) {
  double points = 0;
  for (const auto& box : boxes) {
    const auto d = grown_dims(box);
    points += double(d[0]) * double(d[1]) * double(d[2]);
  }
  return points <= 4 * double(dims[0]) * double(dims[1]) * double(dims[2]);
}

MaterialBits::MaterialBits(const MaterialRows& rows, std::span<const PartBox> boxes) {
  size_t words = 0;
  parts_.reserve(boxes.size());
  for (const auto& box : boxes) {
    Part p;
    p.dims = grown_dims(box);
    p.origin = {box[0][0] - 2, box[0][1] - 2, box[0][2] - 2};
    p.words = size_t((p.dims[0] + 63) / 64 + 1);
    p.first_word = words;
    words += p.words * size_t(p.dims[1] * p.dims[2]);
    parts_.push_back(p);
  }
  resize_zeroed(bits_, words);
  const auto& dims = rows.dims();
  tbb::parallel_for(int64_t{0}, dims[2], [&](int64_t k) {
    for (int64_t j = 0; j < dims[1]; ++j)
      for (const MaterialRun& r : rows.row(j, k)) {
        const Part& p = parts_[r.material - 1];
        uint64_t* row = bits_.data() + p.first_word +
                        size_t((k - p.origin[2]) * p.dims[1] + (j - p.origin[1])) * p.words;
        set_bit_run(row, r.x_begin - p.origin[0], r.x_end - p.origin[0]);
      }
  });
}

}  // namespace segmesh::dc
