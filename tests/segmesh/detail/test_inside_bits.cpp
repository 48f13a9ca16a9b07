// Inside bits: a component's bits from its runs equal the bits of its mask, a field's bits follow
// the inside test, and the bit readers cross word boundaries.
#include "segmesh/detail/inside_bits.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <vector>

#include "segmesh/component_field.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

TEST(InsideBits, ComponentRunsGiveTheBitsOfItsMask) {
  const LabelVolume labels = test::random_labels({131, 9, 7}, 2, 0.5, 3);
  const Components c = find_components(labels, {});
  ASSERT_GT(c.components.size(), 2u);
  for (const Component& part : c.components) {
    const Volume<uint8_t> mask = component_mask(labels.grid, c, part);
    const InsideBits runs = inside_bits(c, part);
    const InsideBits field = inside_bits(mask, 0.5);
    ASSERT_EQ(runs.dims, mask.grid.dims);
    EXPECT_EQ(runs.bits, field.bits);
    const auto& d = mask.grid.dims;
    for (int64_t k = 0; k < d[2]; ++k) {
      for (int64_t j = 0; j < d[1]; ++j) {
        for (int64_t i = 0; i < d[0]; ++i) ASSERT_EQ(runs.at(i, j, k), mask.at(i, j, k) != 0);
      }
    }
  }
}

TEST(InsideBits, FieldBitsFollowTheInsideTest) {
  Volume<float> f;
  f.grid.dims = {70, 2, 1};
  f.voxels.resize(140);
  for (size_t n = 0; n < f.voxels.size(); ++n) f.voxels[n] = float(n % 5) - 2.0f;  // -2 .. 2
  f.voxels[64] = std::numeric_limits<float>::quiet_NaN();
  const InsideBits b = inside_bits(f, 0.5);
  EXPECT_EQ(b.words, 3);  // two words of points and the zero word after them
  for (int64_t j = 0; j < 2; ++j) {
    for (int64_t i = 0; i < 70; ++i) {
      const float v = f.at(i, j, 0);
      EXPECT_EQ(b.at(i, j, 0), v >= 0.5f) << i << " " << j;  // NaN is outside
    }
    EXPECT_EQ(b.row(j, 0)[2], 0u);
  }
}

TEST(InsideBits, ReadersCrossWordBoundaries) {
  const uint64_t row[3] = {uint64_t{1} << 63, 0b101, 0};  // bits 63, 64 and 66
  EXPECT_EQ(bit_pair(row, 62), 0b10u);
  EXPECT_EQ(bit_pair(row, 63), 0b11u);
  EXPECT_EQ(bit_pair(row, 64), 0b01u);
  EXPECT_EQ(shifted_word(row, 0), uint64_t{1} << 62 | uint64_t{1} << 63);
}

TEST(InsideBits, ColumnCodesTransposeSixteenRows) {
  std::mt19937_64 rng(5);
  std::vector<uint64_t> words(16 * 3);
  for (auto& w : words) w = rng();
  words[3] = 0, words[7] = ~uint64_t{0};  // rows 1 (word 0) and 2 (word 1) constant
  const uint64_t* rows[16];
  for (int n = 0; n < 16; ++n) rows[n] = words.data() + 3 * n;
  for (int64_t w = 0; w < 3; ++w) {
    uint16_t codes[64];
    column_codes(rows, w, codes);
    ColumnBytes bytes;
    column_bytes(rows, w, bytes);
    for (int b = 0; b < 64; ++b) {
      ASSERT_EQ(column_code(bytes, b), codes[b]) << "word " << w << " bit " << b;
      ASSERT_EQ(column_at(rows, 64 * w + b), codes[b]) << "word " << w << " bit " << b;
    }
    for (int b = 0; b < 64; ++b) {
      for (int n = 0; n < 16; ++n) {
        ASSERT_EQ(codes[b] >> n & 1, rows[n][w] >> b & 1)
            << "word " << w << " bit " << b << " row " << n;
      }
    }
  }
}

}  // namespace
}  // namespace segmesh
