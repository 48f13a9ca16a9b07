// read_volume on NRRD: dcmqi label maps, 3D Slicer .seg.nrrd segment metadata, detached headers
// and broken files.
#include <cmath>

#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::Bytes;
using volume_test::expect_error;
namespace fs = std::filesystem;

LabelVolume labels_of(const Image& image) { return image.labels_int32(); }

Bytes header_bytes(const std::string& text) {
  return Bytes(text.begin(), text.end());
}

Bytes gzip_bytes(const Bytes& data, const fs::path& scratch) {
  const fs::path temp = scratch / "temp.gz";
  volume_test::write_gzip(temp, data);
  Bytes bytes = volume_test::read_bytes(temp);
  fs::remove(temp);
  return bytes;
}

const std::string segmentation_header =
    "NRRD0004\n"
    "# Complete NRRD file format specification at:\n"
    "type: unsigned char\n"
    "dimension: 3\n"
    "space: left-posterior-superior\n"
    "sizes: 4 3 2\n"
    "space directions: (0,2,0) (-1,0,0) (0,0,3)\n"
    "kinds: domain domain domain\n"
    "encoding: raw\n"
    "space origin: (10,20,30)\n"
    "Segment0_Color:=0.9 0.8 0.7\n"
    "Segment0_ID:=Segment_1\n"
    "Segment0_LabelValue:=1\n"
    "Segment0_Layer:=0\n"
    "Segment0_Name:=femur\n"
    "Segment1_Color:=0.2 0.3 1\n"
    "Segment1_ID:=Segment_2\n"
    "Segment1_LabelValue:=2\n"
    "Segment1_Layer:=0\n"
    "Segment1_Name:=plate\n"
    "Segment2_Color:=1 0 0\n"
    "Segment2_ID:=Segment_3\n"
    "Segment2_LabelValue:=5\n"
    "Segment2_Layer:=0\n"
    "Segment2_Name:=screw 1\n"
    "\n";

TEST(ReadVolumeNrrd, DcmqiLabelMaps) {
  SEGMESH_DATA_FILE(liver_spine, "dcmqi/liver_spine_seg.nrrd");
  SEGMESH_DATA_FILE(label5, "dcmqi/spine_seg_label5.nrrd");
  const Image image = read_volume(liver_spine);
  EXPECT_EQ(image.voxel_type, "int16");
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{512, 512, 3}));
  EXPECT_NEAR(grid.spacing[0], 0.810547, 1e-6);
  EXPECT_NEAR(grid.spacing[1], 0.810547, 1e-6);
  EXPECT_NEAR(grid.spacing[2], 1.0, 1e-9);
  EXPECT_NEAR(grid.origin[0], -235.199997, 1e-6);
  EXPECT_NEAR(grid.origin[1], -226.800003, 1e-6);
  EXPECT_NEAR(grid.origin[2], -128.690002, 1e-6);
  EXPECT_EQ(grid.direction, identity3());
  EXPECT_EQ(volume_test::label_set(labels_of(image)), (std::set<int32_t>{0, 1, 2}));
  EXPECT_TRUE(image.labels.empty());
  EXPECT_EQ(volume_test::label_set(labels_of(read_volume(label5))), (std::set<int32_t>{0, 5}));
}

TEST(ReadVolumeNrrd, SlicerSegmentationGivesNamesColoursAndLabelValues) {
  const fs::path dir = test::scratch_dir("nrrd_seg");
  Bytes file = header_bytes(segmentation_header);
  const Bytes voxels = {0, 1, 1, 0, 2, 2, 0, 5, 0, 0, 0, 0, 1, 1, 1, 1, 2, 0, 0, 5, 5, 0, 0, 0};
  file.insert(file.end(), voxels.begin(), voxels.end());
  volume_test::write_bytes(dir / "case.seg.nrrd", file);

  const Image image = read_volume(dir / "case.seg.nrrd");
  EXPECT_EQ(image.voxel_type, "uint8");
  EXPECT_EQ(labels_of(image).voxels, std::vector<int32_t>(voxels.begin(), voxels.end()));
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{4, 3, 2}));
  EXPECT_EQ(grid.spacing, (std::array<double, 3>{2, 1, 3}));
  EXPECT_EQ(grid.origin, (std::array<double, 3>{10, 20, 30}));
  // Axis 0 runs along +P, axis 1 along -L: columns (0,1,0), (-1,0,0), (0,0,1).
  const Mat3d expected{0, -1, 0, 1, 0, 0, 0, 0, 1};
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(grid.direction[i], expected[i], 1e-12);

  ASSERT_EQ(image.labels.size(), 3u);
  EXPECT_EQ(image.labels[0].label, 1);
  EXPECT_EQ(image.labels[0].name, "femur");
  ASSERT_TRUE(image.labels[0].color);
  EXPECT_FLOAT_EQ(image.labels[0].color->r, 0.9f);
  EXPECT_FLOAT_EQ(image.labels[0].color->g, 0.8f);
  EXPECT_FLOAT_EQ(image.labels[0].color->b, 0.7f);
  EXPECT_FALSE(image.labels[0].role);
  EXPECT_EQ(image.labels[1].label, 2);
  EXPECT_EQ(image.labels[1].name, "plate");
  EXPECT_FLOAT_EQ(image.labels[1].color->b, 1.0f);
  EXPECT_EQ(image.labels[2].label, 5);
  EXPECT_EQ(image.labels[2].name, "screw 1");
  EXPECT_FLOAT_EQ(image.labels[2].color->r, 1.0f);
}

TEST(ReadVolumeNrrd, MultiLayerSegmentationIsRefused) {
  const fs::path dir = test::scratch_dir("nrrd_layers");
  Bytes file = header_bytes(
      "NRRD0004\n"
      "type: unsigned char\n"
      "dimension: 4\n"
      "space: left-posterior-superior\n"
      "sizes: 2 4 3 2\n"
      "space directions: none (1,0,0) (0,1,0) (0,0,1)\n"
      "kinds: list domain domain domain\n"
      "encoding: raw\n"
      "space origin: (0,0,0)\n"
      "Segment0_ID:=a\nSegment0_LabelValue:=1\nSegment0_Layer:=0\nSegment0_Name:=bone\n"
      "Segment1_ID:=b\nSegment1_LabelValue:=1\nSegment1_Layer:=1\nSegment1_Name:=implant\n"
      "\n");
  file.resize(file.size() + 48, 1);
  volume_test::write_bytes(dir / "overlap.seg.nrrd", file);
  expect_error(
      [&] { read_volume(dir / "overlap.seg.nrrd"); },
      {"overlap.seg.nrrd: the segments overlap and are stored in 2 layers, which is not supported",
       "Export"});
}

TEST(ReadVolumeNrrd, GzipAndDetachedData) {
  const fs::path dir = test::scratch_dir("nrrd_detached");
  Bytes voxels;
  for (int16_t i = 0; i < 60; ++i)
    volume_test::put<int16_t>(voxels, voxels.size(), int16_t(i * 100 - 3000));
  const std::string fields =
      "type: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 5 4 3\n"
      "space directions: (0.5,0,0) (0,0.5,0) (0,0,2)\nendian: little\nspace origin: (1,2,3)\n";

  Bytes attached = header_bytes("NRRD0004\n" + fields + "encoding: gzip\n\n");
  const Bytes compressed = gzip_bytes(voxels, dir);
  attached.insert(attached.end(), compressed.begin(), compressed.end());
  volume_test::write_bytes(dir / "attached.nrrd", attached);

  volume_test::write_text(dir / "detached.nhdr",
                          "NRRD0004\n" + fields + "encoding: raw\ndata file: detached.raw\n");
  volume_test::write_bytes(dir / "detached.raw", voxels);
  volume_test::write_text(dir / "detached_gz.nhdr",
                          "NRRD0004\n" + fields + "encoding: gzip\ndata file: detached.raw.gz\n");
  volume_test::write_bytes(dir / "detached.raw.gz", compressed);

  for (const char* name : {"attached.nrrd", "detached.nhdr", "detached_gz.nhdr"}) {
    SCOPED_TRACE(name);
    const Image image = read_volume(dir / name);
    EXPECT_EQ(image.voxel_type, "int16");
    EXPECT_EQ(image.grid().spacing, (std::array<double, 3>{0.5, 0.5, 2}));
    EXPECT_EQ(image.grid().origin, (std::array<double, 3>{1, 2, 3}));
    ASSERT_EQ(labels_of(image).voxels.size(), 60u);
    EXPECT_EQ(labels_of(image).voxels[0], -3000);
    EXPECT_EQ(labels_of(image).voxels[59], 2900);
  }

  volume_test::write_text(dir / "lost.nhdr",
                          "NRRD0004\n" + fields + "encoding: raw\ndata file: nowhere.raw\n");
  expect_error([&] { read_volume(dir / "lost.nhdr"); }, {"lost.nhdr: "});
}

// ReadOptions::allow_external_data off (what batch runs over inputs from many sources use): a
// detached header may name data in its own folder (or below it), not elsewhere, whether by an
// absolute path, "../" or a symbolic link out of the folder, in NRRD and MetaImage alike; data
// lists are refused too. Allowed (the default), the same headers read.
TEST(ReadVolumeNrrd, ExternalDataIsRefusedWhenNotAllowed) {
  const fs::path root = test::scratch_dir("external_data");
  const fs::path dir = root / "case";
  fs::create_directories(dir / "sub");
  Bytes voxels;
  for (int16_t i = 0; i < 60; ++i) volume_test::put<int16_t>(voxels, voxels.size(), i);
  const std::string fields =
      "type: short\ndimension: 3\nspace: left-posterior-superior\nsizes: 5 4 3\n"
      "space directions: (1,0,0) (0,1,0) (0,0,1)\nendian: little\nspace origin: (0,0,0)\n";
  volume_test::write_bytes(root / "outside.raw", voxels);
  volume_test::write_bytes(dir / "sub" / "inside.raw", voxels);
  fs::create_symlink(root / "outside.raw", dir / "link.raw");
  const auto nhdr = [&](const std::string& name, const std::string& data) {
    volume_test::write_text(dir / name, "NRRD0004\n" + fields + "encoding: raw\ndata file: " + data + "\n");
  };
  nhdr("inside.nhdr", "sub/inside.raw");
  nhdr("up.nhdr", "../outside.raw");
  nhdr("absolute.nhdr", (root / "outside.raw").string());
  nhdr("link.nhdr", "link.raw");
  nhdr("list.nhdr", "LIST\nsub/inside.raw");
  volume_test::write_text(dir / "up.mhd",
                          "ObjectType = Image\nNDims = 3\nDimSize = 5 4 3\nElementSpacing = 1 1 1\n"
                          "ElementType = MET_SHORT\nElementDataFile = ../outside.raw\n");
  const ReadOptions refuse{.allow_external_data = false};
  EXPECT_EQ(labels_of(read_volume(dir / "inside.nhdr", refuse)).voxels.size(), 60u);
  for (const char* name : {"up.nhdr", "absolute.nhdr", "link.nhdr", "up.mhd"}) {
    SCOPED_TRACE(name);
    expect_error([&] { read_volume(dir / name, refuse); },
                 {std::string(name) + ": its data file \"", "\" lies outside its folder; pass "
                  "--allow-external-data to read it anyway"});
    EXPECT_EQ(labels_of(read_volume(dir / name)).voxels.size(), 60u);  // allowed by default
  }
  expect_error([&] { read_volume(dir / "list.nhdr", refuse); },
               {"list.nhdr: its data are a list or pattern of files", "--allow-external-data"});
}

TEST(ReadVolumeNrrdErrors, Truncated) {
  const fs::path dir = test::scratch_dir("nrrd_truncated");
  const std::string header =
      "NRRD0004\ntype: short\ndimension: 3\nsizes: 10 10 10\nspacings: 1 1 1\nencoding: raw\n"
      "endian: little\n\n";
  Bytes raw = header_bytes(header);
  raw.resize(raw.size() + 1500);
  volume_test::write_bytes(dir / "raw.nrrd", raw);
  expect_error([&] { read_volume(dir / "raw.nrrd"); },
               {"raw.nrrd: file is truncated (expected 2000 bytes of image data, found 1500)"});

  SEGMESH_DATA_FILE(path, "dcmqi/liver_spine_seg.nrrd");
  const Bytes original = volume_test::read_bytes(path);
  volume_test::write_bytes(dir / "cut.nrrd", Bytes(original.begin(), original.begin() + 8000));
  expect_error([&] { read_volume(dir / "cut.nrrd"); },
               {"cut.nrrd: file is truncated (expected 1572864 bytes of image data, found "});

  // A header claiming far more than the file holds is refused before allocating.
  Bytes liar = header_bytes(
      "NRRD0004\ntype: int\ndimension: 3\nsizes: 1000 1000 1000\nspacings: 1 1 1\nencoding: "
      "raw\nendian: little\n\n");
  liar.resize(liar.size() + 64);
  volume_test::write_bytes(dir / "liar.nrrd", liar);
  expect_error(
      [&] { read_volume(dir / "liar.nrrd"); },
      {"liar.nrrd: file is truncated (expected 4000000000 bytes of image data, found 64)"});
}

TEST(ReadVolumeNrrdErrors, GeometryAndDimensions) {
  const fs::path dir = test::scratch_dir("nrrd_geometry");
  auto write = [&](const std::string& name, const std::string& fields, size_t data_bytes) {
    Bytes file = header_bytes("NRRD0004\ntype: unsigned char\nencoding: raw\n" + fields + "\n");
    file.insert(file.end(), data_bytes, 0);
    volume_test::write_bytes(dir / name, file);
    return dir / name;
  };
  const fs::path zero = write("zero.nrrd",
                              "dimension: 3\nsizes: 2 2 2\nspace: left-posterior-superior\n"
                              "space directions: (0,0,0) (0,1,0) (0,0,1)\n",
                              8);
  expect_error([&] { read_volume(zero); },
               {"zero.nrrd: voxel spacing 0 x 1 x 1 is not valid", "space directions"});

  const fs::path flat = write("flat.nrrd", "dimension: 2\nsizes: 8 8\n", 64);
  expect_error([&] { read_volume(flat); }, {"flat.nrrd: 2-D images are not supported (dims 8x8)"});

  const fs::path time =
      write("time.nrrd", "dimension: 4\nsizes: 2 2 2 3\nkinds: domain domain domain domain\n", 24);
  expect_error([&] { read_volume(time); },
               {"time.nrrd: 4-D images are not supported (dims 2x2x2x3)"});

  const fs::path huge = write("huge.nrrd", "dimension: 3\nsizes: 100000 100000 1000\n", 8);
  expect_error([&] { read_volume(huge); }, {"huge.nrrd: 100000x100000x1000", "exceeds the limit"});
}

}  // namespace
}  // namespace segmesh
