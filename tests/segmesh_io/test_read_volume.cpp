// read_volume: dispatch and general errors, and NIfTI (real data, NIfTI-2, byte-swapped and
// broken files).
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

void expect_grid(const Grid& grid, std::array<int64_t, 3> dims, std::array<double, 3> spacing,
                 std::array<double, 3> origin, Mat3d direction, double tolerance = 1e-4) {
  EXPECT_EQ(grid.dims, dims);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(grid.spacing[a], spacing[a], tolerance) << "spacing axis " << a;
    EXPECT_NEAR(grid.origin[a], origin[a], tolerance) << "origin axis " << a;
  }
  for (int i = 0; i < 9; ++i)
    EXPECT_NEAR(grid.direction[i], direction[i], 1e-6) << "direction " << i;
}

LabelVolume labels_of(const Image& image) { return image.labels_int32(); }

// ---------------------------------------------------------------------------------------------
// Real NIfTI data

TEST(ReadVolumeNifti, TotalSegmentatorExampleSeg) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_seg.nii.gz");
  const Image image = read_volume(path);
  EXPECT_EQ(image.voxel_type, "uint8");
  ASSERT_TRUE(image.is_integer());
  // nibabel's affine is diag(3, 3, 3) with offset (-177.956, 11.319, 94.302) in RAS; LPS negates
  // the first two rows.
  expect_grid(image.grid(), {122, 101, 30}, {3, 3, 3},
              {177.95632934570312, -11.319000244140625, 94.3017578125},
              {-1, 0, 0, 0, -1, 0, 0, 0, 1});
  EXPECT_EQ(labels_of(image).voxels.size(), size_t(122 * 101 * 30));
  std::set<int32_t> labels = volume_test::label_set(labels_of(image));
  labels.erase(0);
  EXPECT_EQ(labels.size(), 41u);
  EXPECT_TRUE(labels.count(30) && labels.count(33) && labels.count(98));  // vertebrae and ribs
  EXPECT_TRUE(image.labels.empty());
}

TEST(ReadVolumeNifti, TotalSegmentatorDicomGridIsMirrored) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_seg_dicom.nii.gz");
  const Image image = read_volume(path);
  EXPECT_EQ(image.voxel_type, "uint8");
  // LAS affine diag(-0.977, 0.977, 2): in LPS the y axis points to -P.
  expect_grid(image.grid(), {512, 512, 20}, {0.9765625, 0.9765625, 2.0},
              {-249.51171875, 61.51171875, -804.5}, {1, 0, 0, 0, -1, 0, 0, 0, 1});
  EXPECT_TRUE(image.grid().mirrored());
  EXPECT_NEAR(determinant(image.grid().direction), -1.0, 1e-9);
}

TEST(ReadVolumeNifti, PelvicFractureCase001) {
  SEGMESH_DATA_FILE(dir, "pelvic_fracture/001");
  const std::vector<std::pair<std::string, std::string>> files = {{"001_LI.nii.gz", "int32"},
                                                                  {"001_LI_mask.nii.gz", "uint8"},
                                                                  {"001_RI_mask.nii.gz", "int16"},
                                                                  {"001_SA_mask.nii.gz", "int16"}};
  for (const auto& [name, type] : files) {
    SCOPED_TRACE(name);
    const Image image = read_volume(dir / name);
    // RAS affine diag(-0.863, -0.863, 1): identity in LPS.
    expect_grid(image.grid(), {512, 512, 274}, {0.86328125, 0.86328125, 1.0},
                {-220.568359375, -220.568359375, -237.0374755859375}, identity3());
    EXPECT_EQ(image.voxel_type, type);
    ASSERT_TRUE(image.is_integer());
    if (name == "001_LI_mask.nii.gz") {
      EXPECT_EQ(volume_test::label_set(labels_of(image)), (std::set<int32_t>{0, 1, 3}));
    }
  }
}

TEST(ReadVolumeNifti, IntegerCtStaysIntegerAndFloatFileBecomesScalar) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_ct_sm.nii.gz");
  const Image ct = read_volume(path);
  EXPECT_EQ(ct.voxel_type, "int16");
  ASSERT_TRUE(ct.is_integer());
  const auto [low, high] = std::ranges::minmax(labels_of(ct).voxels);
  EXPECT_LT(low, -500);  // air in HU
  EXPECT_GT(high, 500);  // bone

  // The same voxels stored as float32 come back as a ScalarVolume with equal values.
  const Bytes original = volume_test::gunzip(path);
  ASSERT_EQ(volume_test::get<int16_t>(original, 70), 4);
  Bytes as_float(original.begin(), original.begin() + 352);
  volume_test::put<int16_t>(as_float, 70, 16);
  volume_test::put<int16_t>(as_float, 72, 32);
  for (size_t i = 352; i + 1 < original.size(); i += 2) {
    const float v = volume_test::get<int16_t>(original, i);
    volume_test::put<float>(as_float, as_float.size(), v);
  }
  const fs::path out = test::scratch_dir("nifti_float") / "ct_float.nii.gz";
  volume_test::write_gzip(out, as_float);
  const Image scalar = read_volume(out);
  EXPECT_EQ(scalar.voxel_type, "float32");
  ASSERT_FALSE(scalar.is_integer());
  const auto& floats = std::get<ScalarVolume>(scalar.volume).voxels;
  const LabelVolume ct_values = labels_of(ct);
  ASSERT_EQ(floats.size(), ct_values.voxels.size());
  for (size_t i = 0; i < floats.size(); i += 997) EXPECT_EQ(floats[i], float(ct_values.voxels[i]));
  EXPECT_EQ(scalar.grid().origin, ct.grid().origin);
}

// ---------------------------------------------------------------------------------------------
// NIfTI variants built from the real files

// NIfTI-1 header fields and their sizes, to byte-swap a header.
const std::vector<std::pair<size_t, size_t>> nifti1_fields = {
    {0, 4},   {32, 4},  {36, 2},  {40, 2},  {42, 2},  {44, 2},  {46, 2},  {48, 2},
    {50, 2},  {52, 2},  {54, 2},  {56, 4},  {60, 4},  {64, 4},  {68, 2},  {70, 2},
    {72, 2},  {74, 2},  {76, 4},  {80, 4},  {84, 4},  {88, 4},  {92, 4},  {96, 4},
    {100, 4}, {104, 4}, {108, 4}, {112, 4}, {116, 4}, {120, 2}, {124, 4}, {128, 4},
    {132, 4}, {136, 4}, {140, 4}, {144, 4}, {252, 2}, {254, 2}};

TEST(ReadVolumeNifti, BigEndianFileReadsLikeTheOriginal) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_ct_sm.nii.gz");
  Bytes bytes = volume_test::gunzip(path);
  ASSERT_EQ(volume_test::get<float>(bytes, 108), 352.0f);
  auto swap = [&](size_t offset, size_t size) {
    std::reverse(bytes.begin() + offset, bytes.begin() + offset + size);
  };
  for (auto [offset, size] : nifti1_fields) swap(offset, size);
  for (size_t offset = 256; offset < 328; offset += 4) swap(offset, 4);  // quatern, qoffset, srow
  for (size_t offset = 352; offset + 1 < bytes.size(); offset += 2)
    swap(offset, 2);  // int16 voxels
  const fs::path out = test::scratch_dir("nifti_big_endian") / "ct_be.nii";
  volume_test::write_bytes(out, bytes);

  const Image original = read_volume(path);
  const Image swapped = read_volume(out);
  EXPECT_EQ(swapped.voxel_type, "int16");
  EXPECT_EQ(swapped.grid().dims, original.grid().dims);
  EXPECT_EQ(swapped.grid().origin, original.grid().origin);
  EXPECT_EQ(swapped.grid().direction, original.grid().direction);
  EXPECT_EQ(labels_of(swapped).voxels, labels_of(original).voxels);
}

// Rewrites a NIfTI-1 file (no extensions needed) as NIfTI-2 with the same sform and voxels.
Bytes to_nifti2(const Bytes& v1) {
  Bytes h(544, 0);
  volume_test::put<int32_t>(h, 0, 540);
  std::memcpy(h.data() + 4, "n+2\0\r\n\032\n", 8);
  volume_test::put<int16_t>(h, 12, volume_test::get<int16_t>(v1, 70));
  volume_test::put<int16_t>(h, 14, volume_test::get<int16_t>(v1, 72));
  for (int i = 0; i < 8; ++i)
    volume_test::put<int64_t>(h, 16 + 8 * i, volume_test::get<int16_t>(v1, 40 + 2 * i));
  for (int i = 0; i < 8; ++i)
    volume_test::put<double>(h, 104 + 8 * i, volume_test::get<float>(v1, 76 + 4 * i));
  volume_test::put<int64_t>(h, 168, 544);
  volume_test::put<double>(h, 176, volume_test::get<float>(v1, 112));
  volume_test::put<double>(h, 184, volume_test::get<float>(v1, 116));
  volume_test::put<int32_t>(h, 344, volume_test::get<int16_t>(v1, 252));
  volume_test::put<int32_t>(h, 348, volume_test::get<int16_t>(v1, 254));
  for (int i = 0; i < 6; ++i)
    volume_test::put<double>(h, 352 + 8 * i, volume_test::get<float>(v1, 256 + 4 * i));
  for (int i = 0; i < 12; ++i)
    volume_test::put<double>(h, 400 + 8 * i, volume_test::get<float>(v1, 280 + 4 * i));
  const auto vox_offset = size_t(volume_test::get<float>(v1, 108));
  h.insert(h.end(), v1.begin() + std::ptrdiff_t(vox_offset), v1.end());
  return h;
}

TEST(ReadVolumeNifti, Nifti2MatchesNifti1) {
  SEGMESH_DATA_FILE(seg_path, "totalsegmentator/example_seg.nii.gz");
  SEGMESH_DATA_FILE(pelvis_path, "pelvic_fracture/002/002_LI_mask.nii.gz");
  const fs::path dir = test::scratch_dir("nifti2");
  for (const fs::path& path : {seg_path, pelvis_path}) {
    SCOPED_TRACE(path.filename().string());
    const fs::path out = dir / ("v2_" + path.filename().string());
    volume_test::write_gzip(out, to_nifti2(volume_test::gunzip(path)));
    const Image v1 = read_volume(path);
    const Image v2 = read_volume(out);
    expect_grid(v2.grid(), v1.grid().dims, v1.grid().spacing, v1.grid().origin, v1.grid().direction,
                1e-4);
    EXPECT_EQ(v2.voxel_type, v1.voxel_type);
    EXPECT_EQ(labels_of(v2).voxels, labels_of(v1).voxels);
  }
}

TEST(ReadVolumeNifti, RescaleKeepsWholeNumbersInteger) {
  const fs::path dir = test::scratch_dir("nifti_rescale");
  Bytes h = volume_test::nifti1_header({4, 3, 2}, 4, 16);
  for (int16_t i = 0; i < 24; ++i) volume_test::put<int16_t>(h, h.size(), i);
  volume_test::put<float>(h, 112, 2.0f);   // scl_slope
  volume_test::put<float>(h, 116, -1.0f);  // scl_inter
  volume_test::write_bytes(dir / "doubled.nii", h);
  const Image doubled = read_volume(dir / "doubled.nii");
  EXPECT_EQ(doubled.voxel_type, "int16");
  ASSERT_TRUE(doubled.is_integer());
  EXPECT_EQ(labels_of(doubled).voxels[5], 9);

  volume_test::put<float>(h, 112, 0.5f);
  volume_test::write_bytes(dir / "halved.nii", h);
  const Image halved = read_volume(dir / "halved.nii");
  ASSERT_FALSE(halved.is_integer());
  EXPECT_FLOAT_EQ(std::get<ScalarVolume>(halved.volume).voxels[5], 1.5f);
}

TEST(ReadVolumeNifti, FourDimensionalFileWithOneVolumeIsRead) {
  Bytes h = volume_test::nifti1_header({3, 2, 2, 1}, 2, 8);
  h.resize(352 + 12, 7);
  const fs::path out = test::scratch_dir("nifti_4d_one") / "one.nii";
  volume_test::write_bytes(out, h);
  const Image image = read_volume(out);
  EXPECT_EQ(image.grid().dims, (std::array<int64_t, 3>{3, 2, 2}));
  EXPECT_EQ(volume_test::label_set(labels_of(image)), (std::set<int32_t>{7}));
}

// ---------------------------------------------------------------------------------------------
// Broken NIfTI files

TEST(ReadVolumeNiftiErrors, TruncatedGzip) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_seg.nii.gz");
  const fs::path dir = test::scratch_dir("nifti_truncated");
  const Bytes compressed = volume_test::read_bytes(path);

  volume_test::write_bytes(
      dir / "half.nii.gz",
      Bytes(compressed.begin(), compressed.begin() + std::ptrdiff_t(compressed.size() / 2)));
  expect_error([&] { read_volume(dir / "half.nii.gz"); },
               {"half.nii.gz: file is truncated (expected 369660 bytes of image data, found "});

  // Every voxel present, only the gzip trailer (CRC and length) missing: still refused.
  volume_test::write_bytes(dir / "no_trailer.nii.gz",
                           Bytes(compressed.begin(), compressed.end() - 6));
  expect_error([&] { read_volume(dir / "no_trailer.nii.gz"); },
               {"no_trailer.nii.gz: file is truncated"});

  // A corrupt stream.
  Bytes corrupt = compressed;
  for (size_t i = 2000; i < 2100; ++i) corrupt[i] ^= 0x5a;
  volume_test::write_bytes(dir / "corrupt.nii.gz", corrupt);
  expect_error([&] { read_volume(dir / "corrupt.nii.gz"); }, {"corrupt.nii.gz: "});

  const Bytes raw = volume_test::gunzip(path);
  volume_test::write_bytes(dir / "cut.nii", Bytes(raw.begin(), raw.end() - 1000));
  expect_error([&] { read_volume(dir / "cut.nii"); },
               {"cut.nii: file is truncated (expected 369660 bytes of image data, found 368660)"});
}

TEST(ReadVolumeNiftiErrors, ZeroAndNonFinitePixdim) {
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_seg.nii.gz");
  const fs::path dir = test::scratch_dir("nifti_pixdim");
  Bytes bytes = volume_test::gunzip(path);
  volume_test::put<float>(bytes, 84, 0.0f);  // pixdim[2]
  volume_test::write_gzip(dir / "zero.nii.gz", bytes);
  expect_error([&] { read_volume(dir / "zero.nii.gz"); },
               {"zero.nii.gz: voxel spacing 3 x 0 x 3 is not valid", "pixdim"});
  volume_test::put<float>(bytes, 84, -3.0f);
  volume_test::write_gzip(dir / "negative.nii.gz", bytes);
  expect_error([&] { read_volume(dir / "negative.nii.gz"); }, {"voxel spacing 3 x -3 x 3"});
  volume_test::put<float>(bytes, 84, std::nanf(""));
  volume_test::write_gzip(dir / "nan.nii.gz", bytes);
  expect_error([&] { read_volume(dir / "nan.nii.gz"); }, {"nan.nii.gz: voxel spacing"});
}

TEST(ReadVolumeNiftiErrors, WrongDimensionCounts) {
  const fs::path dir = test::scratch_dir("nifti_dims");
  Bytes four_d = volume_test::nifti1_header({10, 10, 10, 3}, 2, 8);
  four_d.resize(352 + 3000);
  volume_test::write_bytes(dir / "ct.nii", four_d);
  expect_error(
      [&] { read_volume(dir / "ct.nii"); },
      {"ct.nii: 4-D images are not supported (dims 10x10x10x3); extract one volume first"});

  Bytes two_d = volume_test::nifti1_header({64, 64}, 2, 8);
  two_d.resize(352 + 64 * 64);
  volume_test::write_bytes(dir / "slice.nii", two_d);
  expect_error([&] { read_volume(dir / "slice.nii"); },
               {"slice.nii: 2-D images are not supported (dims 64x64)"});

  Bytes zero = volume_test::nifti1_header({10, 0, 10}, 2, 8);
  volume_test::write_bytes(dir / "zero.nii", zero);
  expect_error([&] { read_volume(dir / "zero.nii"); }, {"zero.nii: ", "10x0x10"});
}

TEST(ReadVolumeNiftiErrors, HugeDimensionsFailBeforeAllocating) {
  const fs::path dir = test::scratch_dir("nifti_huge");
  // More voxels than max_voxels.
  Bytes huge = volume_test::nifti1_header({30000, 30000, 30000}, 2, 8);
  huge.resize(1000);
  volume_test::write_bytes(dir / "huge.nii", huge);
  expect_error([&] { read_volume(dir / "huge.nii"); },
               {"huge.nii: 30000x30000x30000", "exceeds the limit of 2000000000 voxels"});
  volume_test::write_gzip(dir / "huge.nii.gz", huge);
  expect_error([&] { read_volume(dir / "huge.nii.gz"); }, {"exceeds the limit"});

  // Under the limit (1.6e9 voxels, 6.4 GB as int32) but the file holds a few bytes: refused
  // before allocating, so this is fast and does not run out of memory.
  Bytes liar = volume_test::nifti1_header({2000, 2000, 400}, 2, 8);
  liar.resize(5000);
  volume_test::write_bytes(dir / "liar.nii", liar);
  expect_error(
      [&] { read_volume(dir / "liar.nii"); },
      {"liar.nii: file is truncated (expected 1600000000 bytes of image data, found 4648)"});
  volume_test::write_gzip(dir / "liar.nii.gz", liar);
  expect_error([&] { read_volume(dir / "liar.nii.gz"); }, {"liar.nii.gz: file is truncated"});

  // A caller's own limit.
  SEGMESH_DATA_FILE(path, "totalsegmentator/example_seg.nii.gz");
  ReadOptions options;
  options.max_voxels = 100000;
  expect_error([&] { read_volume(path, options); },
               {"122x101x30", "exceeds the limit of 100000 voxels"});
}

TEST(ReadVolumeNiftiErrors, UnsupportedOrOutOfRangeValues) {
  const fs::path dir = test::scratch_dir("nifti_types");
  Bytes rgb = volume_test::nifti1_header({2, 2, 2}, 128, 24);
  rgb.resize(352 + 24);
  volume_test::write_bytes(dir / "rgb.nii", rgb);
  expect_error([&] { read_volume(dir / "rgb.nii"); },
               {"rgb.nii: voxel type RGB24 (NIfTI datatype 128) is not supported"});

  Bytes big = volume_test::nifti1_header({2, 2, 2}, 768, 32);  // uint32
  for (uint32_t i = 0; i < 8; ++i)
    volume_test::put<uint32_t>(big, big.size(), i == 5 ? 3'000'000'000u : i);
  volume_test::write_bytes(dir / "big.nii", big);
  expect_error([&] { read_volume(dir / "big.nii"); },
               {"big.nii: voxel value 3000000000 does not fit a 32-bit signed integer"});

  Bytes fine = volume_test::nifti1_header({2, 2, 2}, 1024, 64);  // int64 within range
  for (int64_t i = 0; i < 8; ++i) volume_test::put<int64_t>(fine, fine.size(), -i * 1000000);
  volume_test::write_bytes(dir / "fine.nii", fine);
  const Image image = read_volume(dir / "fine.nii");
  EXPECT_EQ(image.voxel_type, "int64");
  EXPECT_EQ(labels_of(image).voxels[7], -7000000);
}

// ITK inverts the sform in single precision (vnl's SVD); an element of 2^127 or more never lets
// the SVD converge (fuzz_nifti: a timeout), a NaN aborts the process. Both are refused before ITK
// reads the header, as is any orientation number beyond 1e15.
TEST(ReadVolumeNiftiErrors, AbsurdOrientationNumbersAreRefusedBeforeItk) {
  const fs::path dir = test::scratch_dir("nifti_orientation");
  auto file = [&](const std::string& name, size_t offset, float value, int16_t qform_code = 0) {
    Bytes bytes = volume_test::nifti1_header({2, 2, 2}, 2, 8);
    bytes.resize(352 + 8, 1);
    volume_test::put<int16_t>(bytes, 252, qform_code);
    volume_test::put<float>(bytes, offset, value);
    volume_test::write_bytes(dir / name, bytes);
    return dir / name;
  };
  expect_error([&] { read_volume(file("huge.nii", 288, -std::ldexp(1.0f, 127))); },
               {"huge.nii: the image orientation (qform / sform) holds the number -1.70141e+38, "
                "far beyond any coordinate (at most 1e15); the header is corrupt"});
  expect_error([&] { read_volume(file("offset.nii", 292, 3e38f)); },  // srow_x[3], a translation
               {"offset.nii: ", "3e+38, far beyond any coordinate"});
  expect_error([&] { read_volume(file("nan.nii", 296, std::nanf(""))); },
               {"nan.nii: ", "not finite"});
  expect_error([&] { read_volume(file("qoffset.nii", 268, 1e20f, 1)); },
               {"qoffset.nii: ", "1e+20, far beyond any coordinate"});
  // Large but sane coordinates are read.
  const Image image = read_volume(file("far.nii", 292, 1e6f));
  EXPECT_NEAR(image.grid().origin[0], -1e6, 1e-3);  // RAS to LPS
}

TEST(ReadVolumeNiftiErrors, NotNifti) {
  const fs::path dir = test::scratch_dir("nifti_garbage");
  volume_test::write_text(dir / "text.nii", std::string(400, 'x'));
  expect_error([&] { read_volume(dir / "text.nii"); }, {"text.nii: not a NIfTI file"});
  volume_test::write_text(dir / "short.nii.gz", "abc");
  expect_error([&] { read_volume(dir / "short.nii.gz"); }, {"short.nii.gz: not a NIfTI file"});
}

// ---------------------------------------------------------------------------------------------
// Dispatch

TEST(ReadVolumeErrors, UnknownMissingEmpty) {
  const fs::path dir = test::scratch_dir("read_volume_dispatch");
  volume_test::write_text(dir / "x.foo", "data");
  expect_error(
      [&] { read_volume(dir / "x.foo"); },
      {(dir / "x.foo").string() + ": unknown volume format; expected .nii, .nii.gz, .nrrd, .nhdr, "
                                  ".seg.nrrd, .mha, .mhd, .mrc, .map, .rec, a DICOM SEG file or a "
                                  "DICOM folder"});
  expect_error([&] { read_volume(dir / "x.nii.gz"); },
               {(dir / "x.nii.gz").string() + ": no such file"});
  volume_test::write_text(dir / "empty.nrrd", "");
  expect_error([&] { read_volume(dir / "empty.nrrd"); }, {"empty.nrrd: file is empty"});
  volume_test::write_text(dir / "one.dcm", "x");
  // Named .dcm but not DICOM at all (a DICOM file that is not a DICOM SEG object asks for its
  // series' folder: test_read_volume_dicom_seg.cpp).
  expect_error([&] { read_volume(dir / "one.dcm"); }, {"one.dcm: is not a DICOM file"});
}

TEST(ReadVolumeErrors, NoItkExceptionEscapes) {
  // A NRRD header ITK itself rejects.
  const fs::path dir = test::scratch_dir("read_volume_itk_error");
  volume_test::write_text(
      dir / "bad.nrrd",
      "NRRD0004\ntype: what\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n12345678");
  expect_error([&] { read_volume(dir / "bad.nrrd"); }, {"bad.nrrd: cannot read the header ("});
}

}  // namespace
}  // namespace segmesh

namespace segmesh {
namespace {

// check_volume_geometry: the readers' checks for volumes from elsewhere (the Python package's
// arrays), with the readers' words.
TEST(CheckVolumeGeometry, AcceptsAThreeDGridAndTrailingAxesOfOne) {
  Grid grid;
  grid.spacing = {0.5, 0.5, 2};
  const std::vector<int64_t> dims{4, 5, 6, 1};
  EXPECT_EQ(check_volume_geometry("array", dims, grid), (std::array<int64_t, 3>{4, 5, 6}));
}

TEST(CheckVolumeGeometry, RefusesWhatTheReadersRefuse) {
  const auto message = [](std::vector<int64_t> dims, Grid grid, uint64_t max_voxels) {
    try {
      check_volume_geometry("array", dims, grid, {.max_voxels = max_voxels});
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Grid ok;
  EXPECT_EQ(message({2, 3, 4, 5}, ok, 1000),
            "array: 4-D images are not supported (dims 2x3x4x5); extract one volume first");
  EXPECT_NE(message({3, 4}, ok, 1000).find("2-D images are not supported"), std::string::npos);
  EXPECT_NE(message({10, 10, 11}, ok, 1000).find("exceeds the limit of 1000 voxels"),
            std::string::npos);
  Grid zero = ok;
  zero.spacing[1] = 0;
  EXPECT_NE(message({2, 2, 2}, zero, 1000).find("array: "), std::string::npos);
  EXPECT_NE(message({2, 2, 2}, zero, 1000), "no error");
  Grid sheared = ok;
  sheared.direction[1] = 0.5;
  EXPECT_NE(message({2, 2, 2}, sheared, 1000).find("not a rotation or mirroring"),
            std::string::npos);
}

}  // namespace
}  // namespace segmesh
