// read_volume on DICOM folders: slice ordering by position, foreign files, several series,
// missing and duplicate slices, rescaled CT, and the LPS agreement with NIfTI.
#include <algorithm>
#include <random>

#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::expect_error;
namespace fs = std::filesystem;

LabelVolume labels_of(const Image& image) { return image.labels_int32(); }

std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir)) files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

struct Warnings {
  std::vector<std::string> messages;
  ReadOptions options() {
    ReadOptions o;
    o.warn = [this](const std::string& w) { messages.push_back(w); };
    return o;
  }
  bool any_contains(const std::string& text) const {
    return std::any_of(messages.begin(), messages.end(),
                       [&](const std::string& m) { return m.find(text) != std::string::npos; });
  }
};

TEST(ReadVolumeDicom, SlicerHeadCt) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  Warnings warnings;
  const Image image = read_volume(dir, warnings.options());
  EXPECT_TRUE(warnings.messages.empty());
  EXPECT_EQ(image.path, dir.string());
  EXPECT_EQ(image.voxel_type, "int16");
  ASSERT_TRUE(image.is_integer());
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{64, 64, 93}));
  EXPECT_NEAR(grid.spacing[0], 3.2, 1e-9);
  EXPECT_NEAR(grid.spacing[1], 3.2, 1e-9);
  EXPECT_NEAR(grid.spacing[2], 1.5, 1e-9);
  // Slices lie at z = 0, 1.5, ..., 138: the origin is the lowest one whatever the file names.
  EXPECT_EQ(grid.origin, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(grid.direction, identity3());
  const auto [low, high] = std::ranges::minmax(labels_of(image).voxels);
  EXPECT_EQ(low, 0);
  EXPECT_EQ(high, 3926);
}

TEST(ReadVolumeDicom, FileNamesDoNotMatter) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  const fs::path shuffled = test::scratch_dir("dicom_shuffled");
  std::vector<fs::path> files = files_in(dir);
  std::vector<size_t> order(files.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937(12345));
  for (size_t i = 0; i < files.size(); ++i) {
    fs::copy_file(files[i], shuffled / ("IM" + std::to_string(order[i])));  // no extension either
  }
  const Image original = read_volume(dir);
  const Image copy = read_volume(shuffled);
  EXPECT_EQ(copy.grid().dims, original.grid().dims);
  EXPECT_EQ(copy.grid().origin, original.grid().origin);
  EXPECT_EQ(copy.grid().spacing, original.grid().spacing);
  EXPECT_TRUE(labels_of(copy).voxels == labels_of(original).voxels);

  // And the order is the spatial one: the first two slices alone are slices 0 and 1.
  const fs::path pair = test::scratch_dir("dicom_pair");
  fs::copy_file(dir / "CTHead2.dcm", pair / "a.dcm");
  fs::copy_file(dir / "CTHead1.dcm", pair / "b.dcm");
  const Image two = read_volume(pair);
  ASSERT_EQ(two.grid().dims[2], 2);
  const size_t slice = 64 * 64;
  const auto all = labels_of(original).voxels;
  EXPECT_TRUE(std::equal(all.begin(), all.begin() + 2 * slice, labels_of(two).voxels.begin()));
}

TEST(ReadVolumeDicom, ForeignFilesAreSkippedWithAWarning) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  SEGMESH_DATA_FILE(seg, "dcmqi/liver.dcm");
  const fs::path folder = test::scratch_dir("dicom_foreign");
  for (const fs::path& file : files_in(dir)) fs::copy_file(file, folder / file.filename());
  volume_test::write_text(folder / "notes.txt", "scanned on Tuesday\n");
  fs::copy_file(seg, folder / "liver_seg.dcm");  // a multi-frame DICOM SEG
  Warnings warnings;
  const Image image = read_volume(folder, warnings.options());
  EXPECT_EQ(image.grid().dims, (std::array<int64_t, 3>{64, 64, 93}));
  EXPECT_TRUE(warnings.any_contains("skipping notes.txt: not a DICOM file"));
  EXPECT_TRUE(warnings.any_contains("skipping liver_seg.dcm: a multi-frame object"));
}

TEST(ReadVolumeDicom, TheLargestOfSeveralSeriesIsReadWithAWarning) {
  SEGMESH_DATA_FILE(head, "slicer_ct_head/CTHeadAxialDicom");
  SEGMESH_DATA_FILE(ct, "dcmqi/ct-3slice");
  const fs::path folder = test::scratch_dir("dicom_two_series");
  for (const fs::path& file : files_in(head)) fs::copy_file(file, folder / file.filename());
  for (const fs::path& file : files_in(ct))
    fs::copy_file(file, folder / ("ct_" + file.filename().string()));
  Warnings warnings;
  const Image image = read_volume(folder, warnings.options());
  EXPECT_EQ(image.grid().dims, (std::array<int64_t, 3>{64, 64, 93}));
  ASSERT_EQ(warnings.messages.size(), 1u);
  EXPECT_TRUE(warnings.any_contains("holds 2 series"));
  EXPECT_TRUE(warnings.any_contains(
      "ignoring series 1.2.392.200103.20080913.113635.1.2009.6.22.21.43.10.23430.1 (512x512, 3 "
      "slices)"))
      << warnings.messages[0];
}

TEST(ReadVolumeDicom, RescaledCtInHounsfieldUnits) {
  SEGMESH_DATA_FILE(dir, "dcmqi/ct-3slice");
  const Image image = read_volume(dir);
  EXPECT_EQ(image.voxel_type, "int16");
  ASSERT_TRUE(image.is_integer());  // intercept -1024, slope 1: whole numbers
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, (std::array<int64_t, 3>{512, 512, 3}));
  EXPECT_NEAR(grid.spacing[0], 0.810547, 1e-6);
  EXPECT_NEAR(grid.spacing[2], 1.0, 1e-5);
  // The files list z = -126.69, -127.69, -128.69: the lowest is the origin.
  EXPECT_NEAR(grid.origin[2], -128.690002, 1e-5);
  EXPECT_NEAR(grid.origin[0], -235.199997, 1e-5);
  const auto [low, high] = std::ranges::minmax(labels_of(image).voxels);
  EXPECT_LE(low, -1000);  // air after the -1024 intercept
  EXPECT_GE(high, 200);   // bone

  // Same grid as the dcmqi segmentation made on this CT.
  SEGMESH_DATA_FILE(seg, "dcmqi/liver_spine_seg.nrrd");
  const Grid seg_grid = read_volume(seg).grid();
  EXPECT_EQ(seg_grid.dims, grid.dims);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(seg_grid.origin[a], grid.origin[a], 1e-4);
}

TEST(ReadVolumeDicom, MatchesTheNiftiConversionInWorldSpace) {
  SEGMESH_DATA_FILE(dir, "totalsegmentator/example_ct_dicom");
  SEGMESH_DATA_FILE(nifti, "totalsegmentator/example_seg_dicom.nii.gz");
  const Grid dicom = read_volume(dir).grid();
  const Grid seg = read_volume(nifti).grid();
  EXPECT_EQ(dicom.dims, seg.dims);
  // The NIfTI flips the y axis (LAS), so compare the world positions of the eight corners.
  auto corners = [](const Grid& g) {
    std::vector<std::array<double, 3>> points;
    for (int c = 0; c < 8; ++c) {
      const Vec3d p =
          g.to_world({double((c & 1) * (g.dims[0] - 1)), double((c >> 1 & 1) * (g.dims[1] - 1)),
                      double((c >> 2 & 1) * (g.dims[2] - 1))});
      points.push_back({std::round(p.x * 1000) / 1000, std::round(p.y * 1000) / 1000,
                        std::round(p.z * 1000) / 1000});
    }
    std::sort(points.begin(), points.end());
    return points;
  };
  EXPECT_EQ(corners(dicom), corners(seg));
}

TEST(ReadVolumeDicomErrors, MissingSlice) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  const fs::path folder = test::scratch_dir("dicom_missing_slice");
  for (const fs::path& file : files_in(dir)) {
    if (file.filename() != "CTHead47.dcm") fs::copy_file(file, folder / file.filename());
  }
  expect_error(
      [&] { read_volume(folder); },
      {folder.string() + ": the slices are not evenly spaced: 3 mm between CTHead46.dcm and "
                         "CTHead48.dcm where the others are 1.5 mm apart",
       "missing"});
}

TEST(ReadVolumeDicomErrors, DuplicateSliceAndSingleSlice) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  const fs::path twice = test::scratch_dir("dicom_duplicate");
  for (const fs::path& file : files_in(dir)) fs::copy_file(file, twice / file.filename());
  fs::copy_file(dir / "CTHead10.dcm", twice / "copy_of_10.dcm");
  expect_error([&] { read_volume(twice); }, {"CTHead10.dcm", "copy_of_10.dcm", "same position"});

  const fs::path single = test::scratch_dir("dicom_single");
  fs::copy_file(dir / "CTHead10.dcm", single / "only.dcm");
  expect_error([&] { read_volume(single); }, {"holds only one image slice (only.dcm)"});
}

TEST(ReadVolumeDicomErrors, FolderWithoutDicom) {
  const fs::path empty = test::scratch_dir("dicom_empty");
  expect_error([&] { read_volume(empty); },
               {empty.string() + ": no DICOM images found in this folder"});
  const fs::path text = test::scratch_dir("dicom_text_only");
  volume_test::write_text(text / "readme.txt", "nothing here");
  Warnings warnings;
  expect_error([&] { read_volume(text, warnings.options()); }, {"no DICOM images found"});
  EXPECT_TRUE(warnings.any_contains("skipping readme.txt"));
}

}  // namespace
}  // namespace segmesh
