// read_volume on MRC / CCP4 maps: EMDB maps with plain and permuted axes, byte order, and
// headers that lie.
#include <algorithm>
#include <cmath>

#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::Bytes;
using volume_test::expect_error;
namespace fs = std::filesystem;

const std::vector<float>& floats_of(const Image& image) {
  return std::get<ScalarVolume>(image.volume).voxels;
}

TEST(ReadVolumeMrc, Emd3197PlainHeader) {
  SEGMESH_DATA_FILE(path, "mrc/EMD-3197.map");
  const Image image = read_volume(path);
  EXPECT_EQ(image.voxel_type, "float32");
  ASSERT_FALSE(image.is_integer());
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{20, 20, 20}));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(grid.spacing[a], 11.4, 1e-9);
  // No ORIGIN in the header: start indices (-2, 0, 0) times the voxel size, in ångström.
  EXPECT_NEAR(grid.origin[0], -22.8, 1e-9);
  EXPECT_EQ(grid.origin[1], 0);
  EXPECT_EQ(grid.origin[2], 0);
  EXPECT_EQ(grid.direction, identity3());
  // The header's DMIN / DMAX describe the data.
  const auto [low, high] = std::minmax_element(floats_of(image).begin(), floats_of(image).end());
  EXPECT_FLOAT_EQ(*low, -4.1337456703186035f);
  EXPECT_FLOAT_EQ(*high, 5.576736927032471f);
}

TEST(ReadVolumeMrc, Emd3001PermutedAxes) {
  SEGMESH_DATA_FILE(path, "mrc/EMD-3001.map");
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  const Image image = read_volume(path, options);
  const Grid& grid = image.grid();
  // Columns (73) are z, rows (43) x, sections (25) y: mapc/mapr/maps = 3, 1, 2.
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{43, 25, 73}));
  EXPECT_NEAR(grid.spacing[0], 17.93 / 40, 1e-6);
  EXPECT_NEAR(grid.spacing[1], 4.71 / 12, 1e-6);
  EXPECT_NEAR(grid.spacing[2], 33.03 / 72, 1e-6);
  // Start indices: NRSTART -21 (x), NSSTART -12 (y), NCSTART 0 (z).
  EXPECT_NEAR(grid.origin[0], -21 * 17.93 / 40, 1e-5);
  EXPECT_NEAR(grid.origin[1], -12 * 4.71 / 12, 1e-5);
  EXPECT_EQ(grid.origin[2], 0);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("not orthogonal"), std::string::npos) << warnings[0];

  // Voxel (x, y, z) is the file's value at column z, row x, section y.
  const Bytes raw = volume_test::read_bytes(path);
  const size_t data = 1024 + 160;
  const auto& voxels = floats_of(image);
  for (int64_t x : {0, 7, 42}) {
    for (int64_t y : {0, 13, 24}) {
      for (int64_t z : {0, 31, 72}) {
        const float expected =
            volume_test::get<float>(raw, data + 4 * size_t(z + 73 * (x + 43 * y)));
        EXPECT_EQ(voxels[grid.index(x, y, z)], expected) << x << "," << y << "," << z;
      }
    }
  }
  const auto [low, high] = std::minmax_element(voxels.begin(), voxels.end());
  EXPECT_FLOAT_EQ(*low, -0.3681429624557495f);
  EXPECT_FLOAT_EQ(*high, 0.7216102480888367f);
}

TEST(ReadVolumeMrc, BigEndianAndIntegerModes) {
  SEGMESH_DATA_FILE(path, "mrc/EMD-3197.map");
  const fs::path dir = test::scratch_dir("mrc_variants");
  Bytes bytes = volume_test::read_bytes(path);
  auto swap = [&](size_t offset) {
    std::reverse(bytes.begin() + offset, bytes.begin() + offset + 4);
  };
  for (size_t offset = 0; offset < 96; offset += 4) swap(offset);
  for (size_t offset = 196; offset < 208; offset += 4) swap(offset);
  for (size_t offset = 216; offset < 224; offset += 4) swap(offset);
  bytes[212] = 0x11;
  bytes[213] = 0x11;
  for (size_t offset = 1024; offset < bytes.size(); offset += 4) swap(offset);
  volume_test::write_bytes(dir / "big.mrc", bytes);
  EXPECT_EQ(floats_of(read_volume(dir / "big.mrc")), floats_of(read_volume(path)));

  // Mode 1 (int16) on a 3x2x2 grid with a header ORIGIN: a LabelVolume at that origin.
  Bytes small(1024, 0);
  const int32_t words[] = {3, 2, 2, 1, 0, 0, 0, 3, 2, 2};
  for (int i = 0; i < 10; ++i) volume_test::put<int32_t>(small, 4 * i, words[i]);
  for (int i = 0; i < 3; ++i)
    volume_test::put<float>(small, 40 + 4 * i, float(3 - i) * 1.5f);  // cell
  for (int i = 0; i < 3; ++i) volume_test::put<float>(small, 52 + 4 * i, 90.0f);
  for (int i = 0; i < 3; ++i) volume_test::put<int32_t>(small, 64 + 4 * i, i + 1);
  for (int i = 0; i < 3; ++i) volume_test::put<float>(small, 196 + 4 * i, float(i + 1) * 10);
  small[208] = 'M', small[209] = 'A', small[210] = 'P', small[211] = ' ', small[212] = 0x44,
  small[213] = 0x44;
  for (int16_t v = 0; v < 12; ++v) volume_test::put<int16_t>(small, small.size(), int16_t(v - 6));
  volume_test::write_bytes(dir / "small.mrc", small);
  const Image image = read_volume(dir / "small.mrc");
  EXPECT_EQ(image.voxel_type, "int16");
  ASSERT_TRUE(image.is_integer());
  EXPECT_EQ(image.grid().spacing, (std::array<double, 3>{1.5, 1.5, 0.75}));
  EXPECT_EQ(image.grid().origin, (std::array<double, 3>{10, 20, 30}));
  EXPECT_EQ(image.labels_int32().voxels[11], 5);
}

TEST(ReadVolumeMrcErrors, LyingHeaders) {
  SEGMESH_DATA_FILE(path, "mrc/EMD-3197.map");
  const fs::path dir = test::scratch_dir("mrc_lying");
  const Bytes original = volume_test::read_bytes(path);
  auto patched = [&](const std::string& name, size_t offset, int32_t value) {
    Bytes bytes = original;
    volume_test::put<int32_t>(bytes, offset, value);
    volume_test::write_bytes(dir / name, bytes);
    return dir / name;
  };
  expect_error([&] { read_volume(patched("wide.map", 0, 200)); },
               {"wide.map: file is truncated (expected 320000 bytes of image data, found 32000)"});
  expect_error([&] { read_volume(patched("ext.map", 92, 1 << 20)); },
               {"ext.map: file is truncated"});
  expect_error([&] { read_volume(patched("negext.map", 92, -5)); }, {"negext.map: NSYMBT -5"});
  expect_error([&] { read_volume(patched("huge.map", 0, 10000000)); },
               {"huge.map: ", "exceeds the limit"});
  expect_error([&] { read_volume(patched("mode.map", 12, 9)); },
               {"mode.map: MRC mode 9 is not supported"});
  expect_error([&] { read_volume(patched("axes.map", 68, 1)); },
               {"axes.map: MAPC/MAPR/MAPS = 1,1,3 is not an ordering"});
  expect_error([&] { read_volume(patched("sampling.map", 28, 0)); },
               {"sampling.map: voxel spacing 0 x 11.4 x 11.4 is not valid"});
  expect_error([&] { read_volume(patched("flat.map", 8, 0)); }, {"flat.map: "});
  volume_test::write_bytes(dir / "short.mrc", Bytes(original.begin(), original.begin() + 500));
  expect_error([&] { read_volume(dir / "short.mrc"); }, {"short.mrc: not an MRC/CCP4 map"});
}

}  // namespace
}  // namespace segmesh
