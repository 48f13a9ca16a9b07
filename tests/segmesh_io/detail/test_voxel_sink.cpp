// VoxelSink (voxel_sink.hpp): integer files land in the narrowest store that holds their type, a
// value the store cannot hold widens it (to int32, or to float when it is not a whole number),
// also part way through in-place decoding; values outside int32 are an error.
#include <gtest/gtest.h>

#include <cstring>
#include <variant>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace segmesh::volume_io {
namespace {

Grid line_grid(int64_t n) {
  Grid g;
  g.dims = {n, 1, 1};
  return g;
}

TEST(VoxelSink, NarrowestStorePerFileType) {
  const std::vector<uint8_t> bytes(8, 0);
  auto store_of = [&](VoxelType type, Rescale rescale = {}) {
    VoxelSink sink("f", 8 / voxel_type_size(type), type, rescale);
    sink.append(type, bytes.data(), 8 / voxel_type_size(type));
    return std::move(sink).finish(line_grid(int64_t(8 / voxel_type_size(type)))).index();
  };
  EXPECT_EQ(store_of(VoxelType::uint8), 0u);   // Volume<uint8_t>
  EXPECT_EQ(store_of(VoxelType::int8), 1u);    // Volume<int16_t>
  EXPECT_EQ(store_of(VoxelType::int16), 1u);
  EXPECT_EQ(store_of(VoxelType::uint16), 2u);  // Volume<uint16_t>
  EXPECT_EQ(store_of(VoxelType::int32), 3u);   // Volume<int32_t>
  EXPECT_EQ(store_of(VoxelType::uint32), 3u);
  EXPECT_EQ(store_of(VoxelType::int64), 3u);
  EXPECT_EQ(store_of(VoxelType::uint8, {2, 0}), 3u);  // rescaled: int32
  EXPECT_EQ(store_of(VoxelType::float32), 4u);  // ScalarVolume
}

// DICOM: the sink is made for the file's stored type and fed what ITK returns after the rescale.
TEST(VoxelSink, AValueTheStoreCannotHoldWidensIt) {
  const std::vector<int16_t> values{1, 2, 255, -1024, 3000, 4};
  VoxelSink sink("f", values.size(), VoxelType::uint8);
  sink.append(VoxelType::int16, values.data(), values.size());
  const AnyVolume v = std::move(sink).finish(line_grid(6));
  ASSERT_TRUE(std::holds_alternative<Volume<int32_t>>(v));
  EXPECT_EQ(std::get<Volume<int32_t>>(v).voxels, (std::vector<int32_t>{1, 2, 255, -1024, 3000, 4}));

  const std::vector<float> fractional{1, 2, 2.5f};
  VoxelSink to_float("f", 3, VoxelType::uint16);
  to_float.append(VoxelType::float32, fractional.data(), 3);
  const AnyVolume f = std::move(to_float).finish(line_grid(3));
  ASSERT_TRUE(std::holds_alternative<ScalarVolume>(f));
  EXPECT_EQ(std::get<ScalarVolume>(f).voxels, fractional);
}

TEST(VoxelSink, WideningWhileDecodingInPlaceKeepsEveryValue) {
  // 40000 int16 file values staged in a uint16 store; a negative value far in widens it to int32
  // while the rest of the file bytes still sit in the old store.
  const size_t n = 40000;
  std::vector<int16_t> values(n);
  for (size_t i = 0; i < n; ++i) values[i] = int16_t(i % 30000);
  values[n - 50] = -7;
  VoxelSink sink("f", n, VoxelType::uint16);
  unsigned char* room = sink.stage(0, VoxelType::int16);
  ASSERT_NE(room, nullptr);
  std::memcpy(room, values.data(), n * sizeof(int16_t));
  sink.append_staged(VoxelType::int16, false);
  const AnyVolume v = std::move(sink).finish(line_grid(int64_t(n)));
  ASSERT_TRUE(std::holds_alternative<Volume<int32_t>>(v));
  const auto& got = std::get<Volume<int32_t>>(v).voxels;
  ASSERT_EQ(got.size(), n);
  for (size_t i = 0; i < n; ++i) ASSERT_EQ(got[i], values[i]) << i;
}

TEST(VoxelSink, ValuesOutsideInt32AreAnError) {
  const std::vector<int64_t> values{1, int64_t(1) << 40};
  VoxelSink sink("big.nii", 2, VoxelType::int64);
  try {
    sink.append(VoxelType::int64, values.data(), 2);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not fit a 32-bit signed integer"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace segmesh::volume_io
