// write_volume: round trips through read_volume, the stored type, and atomic writing.
#include <cmath>

#include "segmesh_io/read_volume.hpp"
#include "segmesh_io/write_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::expect_error;
namespace fs = std::filesystem;

// 7x5x4 voxels on an anisotropic grid rotated 30 degrees about z and mirrored in y.
LabelVolume sample_volume(int32_t scale, int32_t offset = 0) {
  LabelVolume volume;
  volume.grid.dims = {7, 5, 4};
  volume.grid.spacing = {0.75, 1.25, 2.5};
  volume.grid.origin = {-120.5, 33.25, -801.0};
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  volume.grid.direction = {c, s, 0, s, -c, 0, 0, 0, 1};  // columns (c,s,0), (s,-c,0), (0,0,1)
  for (size_t i = 0; i < volume.grid.voxel_count(); ++i) {
    volume.voxels.push_back(int32_t(i % 11) * scale + offset);
  }
  return volume;
}

std::vector<std::string> names_in(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

void expect_round_trip(const LabelVolume& volume, const fs::path& path, const std::string& type) {
  SCOPED_TRACE(path.filename().string());
  write_volume(volume, path);
  const Image image = read_volume(path);
  EXPECT_EQ(image.voxel_type, type);
  ASSERT_TRUE(image.is_integer());
  const Grid& grid = image.grid();
  EXPECT_EQ(grid.dims, volume.grid.dims);
  for (int a = 0; a < 3; ++a) {
    // NIfTI keeps the geometry in single precision.
    EXPECT_NEAR(grid.spacing[a], volume.grid.spacing[a], 1e-5);
    EXPECT_NEAR(grid.origin[a], volume.grid.origin[a], 1e-3);
  }
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(grid.direction[i], volume.grid.direction[i], 1e-5) << i;
  EXPECT_TRUE(grid.mirrored());
  EXPECT_EQ(image.labels_int32().voxels, volume.voxels);
}

TEST(WriteVolume, RoundTripsEveryFormat) {
  const fs::path dir = test::scratch_dir("write_volume_round_trip");
  const LabelVolume labels = sample_volume(1);                 // 0..10: uint8
  const LabelVolume signed_values = sample_volume(100, -500);  // -500..500: int16
  const LabelVolume wide = sample_volume(6000);                // 0..60000: uint16
  const LabelVolume huge = sample_volume(100000, -7);          // beyond 16 bits: int32
  for (const char* ext : {".nii.gz", ".nii", ".nrrd", ".mha"}) {
    expect_round_trip(labels, dir / (std::string("labels") + ext), "uint8");
    expect_round_trip(signed_values, dir / (std::string("signed") + ext), "int16");
    expect_round_trip(wide, dir / (std::string("wide") + ext), "uint16");
    expect_round_trip(huge, dir / (std::string("huge") + ext), "int32");
  }
  // Only the outputs: no temporary files left behind.
  for (const std::string& name : names_in(dir)) {
    EXPECT_EQ(name.find(".tmp"), std::string::npos) << name;
  }
  EXPECT_EQ(names_in(dir).size(), 16u);
}

TEST(WriteVolume, CompressesNrrdAndGzippedNifti) {
  const fs::path dir = test::scratch_dir("write_volume_compression");
  LabelVolume volume = sample_volume(1);
  volume.grid.dims = {64, 64, 64};
  volume.voxels.assign(volume.grid.voxel_count(), 0);
  volume.voxels[1000] = 2;
  write_volume(volume, dir / "a.nii.gz");
  write_volume(volume, dir / "a.nrrd");
  write_volume(volume, dir / "a.nii");
  EXPECT_LT(fs::file_size(dir / "a.nii.gz"), 10000u);
  EXPECT_LT(fs::file_size(dir / "a.nrrd"), 10000u);
  EXPECT_GT(fs::file_size(dir / "a.nii"), 64u * 64 * 64);
}

TEST(WriteVolume, ReplacesAnExistingFile) {
  const fs::path dir = test::scratch_dir("write_volume_replace");
  volume_test::write_text(dir / "out.nrrd", "old content");
  write_volume(sample_volume(1), dir / "out.nrrd");
  EXPECT_EQ(read_volume(dir / "out.nrrd").grid().dims, (std::array<int64_t, 3>{7, 5, 4}));
  EXPECT_EQ(names_in(dir), std::vector<std::string>{"out.nrrd"});
}

TEST(WriteVolumeErrors, MissingFolderLeavesNothing) {
  const fs::path dir = test::scratch_dir("write_volume_missing_folder");
  const fs::path target = dir / "no" / "such" / "seg.nii.gz";
  expect_error([&] { write_volume(sample_volume(1), target); },
               {target.string() + ": the folder", "does not exist"});
  EXPECT_FALSE(fs::exists(dir / "no"));
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(WriteVolumeErrors, UnknownExtension) {
  const fs::path dir = test::scratch_dir("write_volume_extension");
  expect_error([&] { write_volume(sample_volume(1), dir / "seg.vtk"); },
               {"seg.vtk: unknown volume format for writing; use .nii, .nii.gz, .nrrd or .mha"});
  EXPECT_TRUE(names_in(dir).empty());
}

TEST(WriteVolumeErrors, InconsistentVolumeIsAProgrammingError) {
  const fs::path dir = test::scratch_dir("write_volume_inconsistent");
  LabelVolume volume = sample_volume(1);
  volume.voxels.pop_back();
  EXPECT_THROW(write_volume(volume, dir / "bad.nrrd"), std::invalid_argument);
  EXPECT_TRUE(names_in(dir).empty());
}

}  // namespace
}  // namespace segmesh
