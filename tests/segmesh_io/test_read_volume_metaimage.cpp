// read_volume on MetaImage (.mha, .mhd): raw, compressed, detached and big-endian data, geometry,
// and broken files.
#include <algorithm>

#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::Bytes;
using volume_test::expect_error;
namespace fs = std::filesystem;

LabelVolume labels_of(const Image& image) { return image.labels_int32(); }

// 5x4x3 int16 values i * 7 - 100, rotated 90 degrees about z and mirrored in z.
const std::string geometry_fields =
    "ObjectType = Image\n"
    "NDims = 3\n"
    "BinaryData = True\n"
    "TransformMatrix = 0 1 0 -1 0 0 0 0 -1\n"
    "Offset = -10 20.5 7\n"
    "ElementSpacing = 0.5 0.75 2.5\n"
    "DimSize = 5 4 3\n"
    "ElementType = MET_SHORT\n";

Bytes voxel_bytes(bool big_endian) {
  Bytes bytes;
  for (int i = 0; i < 60; ++i) {
    int16_t value = int16_t(i * 7 - 100);
    volume_test::put<int16_t>(bytes, bytes.size(), value);
    if (big_endian) std::reverse(bytes.end() - 2, bytes.end());
  }
  return bytes;
}

void expect_volume(const Image& image) {
  EXPECT_EQ(image.voxel_type, "int16");
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{5, 4, 3}));
  EXPECT_EQ(grid.spacing, (std::array<double, 3>{0.5, 0.75, 2.5}));
  EXPECT_EQ(grid.origin, (std::array<double, 3>{-10, 20.5, 7}));
  // TransformMatrix lists the axes' directions one after another (ITK's reading): axis 0 along
  // +y, axis 1 along -x, axis 2 along -z.
  EXPECT_EQ(grid.direction, (Mat3d{0, -1, 0, 1, 0, 0, 0, 0, -1}));
  EXPECT_TRUE(grid.mirrored());
  const auto voxels = labels_of(image).voxels;
  ASSERT_EQ(voxels.size(), 60u);
  for (int i = 0; i < 60; ++i) ASSERT_EQ(voxels[i], i * 7 - 100) << i;
}

TEST(ReadVolumeMetaImage, RawCompressedDetachedAndBigEndian) {
  const fs::path dir = test::scratch_dir("mha_variants");
  Bytes raw = volume_test::Bytes(geometry_fields.begin(), geometry_fields.end());
  volume_test::append(raw, "ElementDataFile = LOCAL\n");
  const Bytes voxels = voxel_bytes(false);
  raw.insert(raw.end(), voxels.begin(), voxels.end());
  volume_test::write_bytes(dir / "raw.mha", raw);

  const Bytes compressed = volume_test::zlib_compress(voxels);
  Bytes packed(geometry_fields.begin(), geometry_fields.end());
  volume_test::append(
      packed, "CompressedData = True\nCompressedDataSize = " + std::to_string(compressed.size()) +
                  "\nElementDataFile = LOCAL\n");
  packed.insert(packed.end(), compressed.begin(), compressed.end());
  volume_test::write_bytes(dir / "packed.mha", packed);

  volume_test::write_text(dir / "detached.mhd",
                          geometry_fields + "ElementDataFile = detached.raw\n");
  volume_test::write_bytes(dir / "detached.raw", voxels);

  Bytes big(geometry_fields.begin(), geometry_fields.end());
  volume_test::append(big, "BinaryDataByteOrderMSB = True\nElementDataFile = LOCAL\n");
  const Bytes big_voxels = voxel_bytes(true);
  big.insert(big.end(), big_voxels.begin(), big_voxels.end());
  volume_test::write_bytes(dir / "big.mha", big);

  for (const char* name : {"raw.mha", "packed.mha", "detached.mhd", "big.mha"}) {
    SCOPED_TRACE(name);
    expect_volume(read_volume(dir / name));
  }
  const Grid grid = read_volume(dir / "raw.mha").grid();
  const Vec3d corner = grid.to_world({4, 3, 2});
  EXPECT_NEAR(corner.x, -10 - 3 * 0.75, 1e-12);
  EXPECT_NEAR(corner.y, 20.5 + 4 * 0.5, 1e-12);
  EXPECT_NEAR(corner.z, 7 - 2 * 2.5, 1e-12);
}

TEST(ReadVolumeMetaImageErrors, Truncated) {
  const fs::path dir = test::scratch_dir("mha_truncated");
  const Bytes voxels = voxel_bytes(false);
  Bytes raw(geometry_fields.begin(), geometry_fields.end());
  volume_test::append(raw, "ElementDataFile = LOCAL\n");
  raw.insert(raw.end(), voxels.begin(), voxels.begin() + 100);
  volume_test::write_bytes(dir / "raw.mha", raw);
  expect_error([&] { read_volume(dir / "raw.mha"); },
               {"raw.mha: file is truncated (expected 120 bytes of image data, found 100)"});

  const Bytes compressed = volume_test::zlib_compress(voxels);
  Bytes packed(geometry_fields.begin(), geometry_fields.end());
  volume_test::append(packed, "CompressedData = True\nElementDataFile = LOCAL\n");
  packed.insert(packed.end(), compressed.begin(),
                compressed.begin() + std::ptrdiff_t(compressed.size() / 2));
  volume_test::write_bytes(dir / "packed.mha", packed);
  expect_error([&] { read_volume(dir / "packed.mha"); }, {"packed.mha: file is truncated"});

  volume_test::write_text(dir / "short.mhd", geometry_fields + "ElementDataFile = short.raw\n");
  volume_test::write_bytes(dir / "short.raw", Bytes(voxels.begin(), voxels.begin() + 50));
  expect_error([&] { read_volume(dir / "short.mhd"); },
               {"short.mhd: file is truncated (expected 120 bytes of image data, found 50)"});

  volume_test::write_text(dir / "lost.mhd", geometry_fields + "ElementDataFile = nowhere.raw\n");
  expect_error([&] { read_volume(dir / "lost.mhd"); },
               {"lost.mhd: ", "nowhere.raw does not exist"});
}

TEST(ReadVolumeMetaImageErrors, HeaderFaults) {
  const fs::path dir = test::scratch_dir("mha_header");
  auto write = [&](const std::string& name, const std::string& header, size_t data_bytes) {
    Bytes file(header.begin(), header.end());
    file.insert(file.end(), data_bytes, 0);
    volume_test::write_bytes(dir / name, file);
    return dir / name;
  };
  const std::string common = "ObjectType = Image\nElementType = MET_UCHAR\n";
  expect_error(
      [&] {
        read_volume(write(
            "zero.mha",
            common +
                "NDims = 3\nDimSize = 2 2 2\nElementSpacing = 0 1 1\nElementDataFile = LOCAL\n",
            8));
      },
      {"zero.mha: voxel spacing 0 x 1 x 1 is not valid (ElementSpacing must be positive and "
       "finite)"});
  expect_error(
      [&] {
        read_volume(write("four.mha",
                          common + "NDims = 4\nDimSize = 2 2 2 3\nElementDataFile = LOCAL\n", 24));
      },
      {"four.mha: 4-D images are not supported (dims 2x2x2x3)"});
  expect_error(
      [&] {
        read_volume(
            write("two.mha", common + "NDims = 2\nDimSize = 4 4\nElementDataFile = LOCAL\n", 16));
      },
      {"two.mha: 2-D images are not supported (dims 4x4)"});
  expect_error(
      [&] {
        read_volume(write("huge.mha",
                          common + "NDims = 3\nDimSize = 5000 5000 5000\nElementDataFile = LOCAL\n",
                          16));
      },
      {"huge.mha: 5000x5000x5000", "exceeds the limit"});
  expect_error(
      [&] {
        read_volume(write("liar.mha",
                          common + "NDims = 3\nDimSize = 1000 1000 1000\nElementDataFile = LOCAL\n",
                          16));
      },
      {"liar.mha: file is truncated (expected 1000000000 bytes of image data, found 16)"});
  expect_error(
      [&] {
        read_volume(write("rgb.mha",
                          common + "NDims = 3\nDimSize = 2 2 2\nElementNumberOfChannels = "
                                   "3\nElementDataFile = LOCAL\n",
                          24));
      },
      {"rgb.mha: images with 3 values per voxel are not supported"});
  expect_error(
      [&] {
        read_volume(write(
            "list.mhd",
            common + "NDims = 3\nDimSize = 2 2 2\nElementDataFile = LIST\na.raw\nb.raw\n", 0));
      },
      {"list.mhd: ", "several files"});
  expect_error([&] { read_volume(write("text.mha", "just text\n", 0)); },
               {"text.mha: not a MetaImage file"});
}

// ITK's MetaIO reads as many numbers as NDims says for DimSize, ElementSpacing, TransformMatrix,
// ..., skipping line ends, and looped forever on an NDims it read as 1e22 (fuzz_mha) while our
// check saw another line. Each field MetaIO reads as numbers is checked first, on the lines MetaIO
// itself takes for the fields; none of these reaches ITK.
TEST(ReadVolumeMetaImageErrors, NumberFieldsAreCheckedBeforeItkReadsThem) {
  const fs::path dir = test::scratch_dir("mha_numbers");
  auto check = [&](const std::string& name, const std::string& fields,
                   std::initializer_list<std::string> parts) {
    SCOPED_TRACE(name);
    Bytes file;
    volume_test::append(file, "ObjectType = Image\n" + fields +
                                  "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n");
    file.insert(file.end(), 8, 0);
    volume_test::write_bytes(dir / name, file);
    expect_error([&] { read_volume(dir / name); }, parts);
  };
  const std::string dims = "NDims = 3\nDimSize = 2 2 2\n";
  // The fuzz finding: MetaIO compares names case-sensitively and took NDims = 1e22; "NDIms"
  // passed the old check.
  check("case.mha", "NDims = 10000000000000000000000\nNDIms = 3\nDimSize = 2 2 2\n",
        {"case.mha: the MetaImage header field \"NDIms\" must be spelled \"NDims\""});
  check("twice.mha", dims + "NDims = -1\n", {"twice.mha: the MetaImage header gives NDims twice"});
  // ':' separates too.
  check("colon.mha", "NDims: -1\nDimSize = 2 2 2\n",
        {"colon.mha: NDims = -1 is not a dimension count (1 to 8)"});
  check("nul.mha", std::string("NDims\0x = 9\n", 12) + dims,
        {"nul.mha: the MetaImage header field name \"NDims?x\" holds a control character"});
  // Too few numbers: MetaIO would go on reading the next line.
  check("few.mha", "NDims = 3\nDimSize = 2 2\n",
        {"few.mha: DimSize = \"2 2\" is not 3 whole numbers (one per dimension, NDims = 3)"});
  check("more.mha", "NDims = 3\nDimSize = 2 2 2 2\n", {"DimSize = \"2 2 2 2\" is not 3"});
  check("text.mha", dims + "ElementSpacing = 1 x 1\n",
        {"text.mha: ElementSpacing = \"1 x 1\" is not 3 numbers"});
  check("nan.mha", dims + "ElementSpacing = nan 1 1\n", {"ElementSpacing = \"nan 1 1\" is not 3"});
  check("matrix.mha", dims + "TransformMatrix = 1 0 0\n",
        {"TransformMatrix = \"1 0 0\" is not 9 numbers (a 3x3 matrix, NDims = 3)"});
  check("color.mha", dims + "Color = 1 0 0\n", {"Color = \"1 0 0\" is not 4 numbers"});
  check("order.mha", "DimSize = 2 2 2\nNDims = 3\n", {"DimSize comes before NDims"});
  check("negative.mha", "NDims = 3\nDimSize = 2 -2 2\n",
        {"DimSize = 2 -2 2: every size must be at least 1"});
  check("fraction.mha", "NDims = 3\nDimSize = 2 2.5 2\n", {"is not 3 whole numbers"});
  check("range.mha", dims + "HeaderSize = 99999999999\n",
        {"HeaderSize = 99999999999 is out of range"});
  check("empty.mha", dims + "ElementMin =\n", {"ElementMin = \"\" is not a number"});

  // What MetaIO accepts besides " = " still reads: ':' as the separator, blank and CRLF lines,
  // signs and exponents.
  Bytes file;
  volume_test::append(file,
                      "ObjectType = Image\r\n\r\nNDims: 3\r\n  DimSize = 2 2 +2\r\n"
                      "Comment = a: b = c\r\nElementSpacing = 0.5 5e-1 .5\r\n"
                      "ElementType = MET_UCHAR\r\nElementDataFile = LOCAL\r\n");
  file.insert(file.end(), 8, 7);
  volume_test::write_bytes(dir / "variants.mha", file);
  const Image image = read_volume(dir / "variants.mha");
  EXPECT_EQ(image.grid().dims, (std::array<int64_t, 3>{2, 2, 2}));
  EXPECT_EQ(image.grid().spacing, (std::array<double, 3>{0.5, 0.5, 0.5}));
  EXPECT_EQ(labels_of(image).voxels, std::vector<int32_t>(8, 7));
}

}  // namespace
}  // namespace segmesh
