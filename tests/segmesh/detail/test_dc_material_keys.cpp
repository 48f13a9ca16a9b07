// The neighbourhood keys of multi-label Dual Contouring's binary cells: from the parts' inside
// bits and from cursors into the runs, against the definition (the 4 x 4 x 4 points around the
// cell holding the material, only those central differences read), for every cell and every part
// at its corners, on random label maps of touching parts and on parts at the volume's border.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/detail/dc_material_keys.hpp"
#include "segmesh/detail/dc_neighbourhood_keys.hpp"
#include "segmesh/detail/material_rows.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

// Every local point's material, from the runs (the box's margin and beyond: background).
struct DenseMaterials {
  std::array<int64_t, 3> dims;
  std::vector<uint32_t> m;
  explicit DenseMaterials(const MaterialRows& rows) : dims(rows.dims()) {
    m.assign(size_t(dims[0] * dims[1] * dims[2]), 0);
    for (int64_t k = 0; k < dims[2]; ++k)
      for (int64_t j = 0; j < dims[1]; ++j)
        for (const MaterialRun& r : rows.row(j, k))
          for (int64_t i = r.x_begin; i < r.x_end; ++i)
            m[size_t((k * dims[1] + j) * dims[0] + i)] = r.material;
  }
  uint32_t at(int64_t i, int64_t j, int64_t k) const {
    if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2]) return 0;
    return m[size_t((k * dims[1] + j) * dims[0] + i)];
  }
};

void expect_keys(const LabelVolume& v, int connectivity, const std::string& what) {
  const Components c = find_components(v, {.connectivity = connectivity});
  std::vector<size_t> parts;
  for (size_t p = 0; p < c.components.size(); ++p) parts.push_back(p);
  const MaterialRows rows(v.grid, c, parts);
  ASSERT_FALSE(rows.empty()) << what;
  const DenseMaterials dense(rows);
  const std::vector<dc::PartBox> boxes = dc::part_boxes(c, parts);
  const dc::MaterialBits bits(rows, boxes);
  const uint64_t mask = dc::key_mask(NormalMethod::central);
  const auto& n = rows.dims();
  int checked = 0;
  for (int64_t k = 0; k + 1 < n[2]; ++k)
    for (int64_t j = 0; j + 1 < n[1]; ++j) {
      for (uint32_t w = 1; w <= parts.size(); ++w) {
        std::array<dc::RowWindow, 12> windows = dc::key_windows(rows, j, k);
        for (int64_t i = 0; i + 1 < n[0]; ++i) {
          bool corner = false;
          for (int q = 0; q < 8; ++q)
            corner |= dense.at(i + (q & 1), j + (q >> 1 & 1), k + (q >> 2)) == w;
          if (!corner) continue;
          uint64_t expected = 0;
          for (int z = 0; z < 4; ++z)
            for (int y = 0; y < 4; ++y)
              for (int x = 0; x < 4; ++x)
                if (dense.at(i - 1 + x, j - 1 + y, k - 1 + z) == w)
                  expected |= dc::key_bit(x, y, z);
          expected &= mask;
          ASSERT_EQ(bits.key(w, i, j, k) & mask, expected)
              << what << " cell " << i << " " << j << " " << k << " material " << w;
          ASSERT_EQ(dc::window_key(windows, i, w) & mask, expected)
              << what << " cell " << i << " " << j << " " << k << " material " << w;
          ++checked;
        }
      }
    }
  EXPECT_GT(checked, 0) << what;
}

TEST(DcMaterialKeys, BitsAndRunsGiveTheKeysOfTheDefinition) {
  for (unsigned seed = 0; seed < 6; ++seed) {
    // Wider than a word along x, so that keys straddle words of the bits.
    const LabelVolume v = test::random_labels({70, 7, 6}, 3, 0.5, seed);
    for (int connectivity : {6, 26})
      expect_keys(
          v, connectivity,
          "seed " + std::to_string(seed) + ", connectivity " + std::to_string(connectivity));
  }
}

TEST(DcMaterialKeys, TouchingBoxesAtTheBorder) {
  LabelVolume v = test::blank_labels({9, 8, 7});
  test::fill_box(v, {0, 0, 0}, {5, 8, 7}, 1);
  test::fill_box(v, {5, 0, 0}, {9, 4, 7}, 2);
  test::fill_box(v, {5, 4, 3}, {9, 8, 4}, 3);
  expect_keys(v, 26, "boxes");
}

}  // namespace
}  // namespace segmesh
