// read_volume on DICOM SEG objects (dicom_seg_reader.hpp): the label map and its place in space
// against the NRRD it was made from, segment names and colours, overlapping segments, a file
// without an extension, and broken or foreign files as one-line errors.
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "segmesh/pipeline.hpp"
#include "segmesh_io/read_volume.hpp"
#include "support/sound_parts.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::expect_error;
namespace fs = std::filesystem;

std::vector<char> bytes_of(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

void write_bytes(const fs::path& file, const std::vector<char>& bytes) {
  std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

// The voxel of `grid` at world point w, when w is (to 1e-3 of a voxel) one of its voxel centres.
std::optional<std::array<int64_t, 3>> voxel_at(const Grid& grid, Vec3d w) {
  const double d[3] = {w.x - grid.origin[0], w.y - grid.origin[1], w.z - grid.origin[2]};
  std::array<int64_t, 3> ijk{};
  for (int c = 0; c < 3; ++c) {
    const double x = (grid.direction[c] * d[0] + grid.direction[3 + c] * d[1] +
                      grid.direction[6 + c] * d[2]) / grid.spacing[c];
    ijk[c] = std::llround(x);
    if (std::abs(x - double(ijk[c])) > 1e-3 || ijk[c] < 0 || ijk[c] >= grid.dims[c]) return std::nullopt;
  }
  return ijk;
}

// dcmqi made liver.dcm from liver_seg.nrrd: every segment voxel must be a liver voxel of the
// NRRD at the same world position, and as many.
TEST(ReadVolumeDicomSeg, LiverLandsOnItsNrrdSourceVoxelForVoxel) {
  SEGMESH_DATA_FILE(seg_file, "dcmqi/liver.dcm");
  SEGMESH_DATA_FILE(nrrd_file, "dcmqi/liver_seg.nrrd");
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  const Image seg = read_volume(seg_file, options);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(seg.voxel_type, "bit");
  ASSERT_TRUE(std::holds_alternative<Volume<uint8_t>>(seg.volume));
  EXPECT_EQ(seg.grid().dims, (std::array<int64_t, 3>{512, 512, 3}));
  ASSERT_EQ(seg.labels.size(), 1u);
  EXPECT_EQ(seg.labels[0].label, 1);
  EXPECT_EQ(seg.labels[0].name, "Liver");
  // Recommended Display CIELab 41661\41167\40792: L 64, a 32, b 30, a light reddish brown.
  ASSERT_TRUE(seg.labels[0].color.has_value());
  EXPECT_GT(seg.labels[0].color->r, seg.labels[0].color->g);
  EXPECT_GT(seg.labels[0].color->g, seg.labels[0].color->b);

  const LabelVolume a = seg.labels_int32();
  const LabelVolume b = read_volume(nrrd_file).labels_int32();
  int64_t in_seg = 0, on_liver = 0, in_nrrd = 0;
  for (int64_t k = 0; k < a.grid.dims[2]; ++k)
    for (int64_t j = 0; j < a.grid.dims[1]; ++j)
      for (int64_t i = 0; i < a.grid.dims[0]; ++i) {
        if (a.at(i, j, k) == 0) continue;
        ++in_seg;
        const auto at = voxel_at(b.grid, a.grid.to_world({double(i), double(j), double(k)}));
        if (at && b.at((*at)[0], (*at)[1], (*at)[2]) != 0) ++on_liver;
      }
  for (int32_t v : b.voxels) in_nrrd += v != 0;
  EXPECT_GT(in_seg, 100000);
  EXPECT_EQ(on_liver, in_seg);
  EXPECT_EQ(in_seg, in_nrrd);
}

// Five segments, three of them overlapping: one warning naming the pairs, each voxel keeps the
// higher segment number, and the scene meshes every segment as a closed part named after it.
TEST(ReadVolumeDicomSeg, OverlappingSegmentsWarnAndMeshAsNamedParts) {
  SEGMESH_DATA_FILE(seg_file, "dcmqi/partial_overlaps.dcm");
  std::vector<std::string> warnings;
  ReadOptions options;
  options.warn = [&](const std::string& w) { warnings.push_back(w); };
  const Image image = read_volume(seg_file, options);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("segments overlap (1 and 2"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[0].find("higher segment number"), std::string::npos) << warnings[0];
  ASSERT_EQ(image.labels.size(), 5u);
  for (size_t s = 0; s < 5; ++s) {
    EXPECT_EQ(image.labels[s].label, int32_t(s + 1));
    EXPECT_FALSE(image.labels[s].name.empty());
  }
  const Scene scene = build_scene(image, {});
  ASSERT_EQ(scene.parts.size(), 5u);
  test::expect_sound_shells(scene);
  EXPECT_EQ(scene.parts[0].name.rfind(image.labels[0].name, 0), 0u) << scene.parts[0].name;
}

// DICOM files often come without an extension: the "DICM" magic says what they are.
TEST(ReadVolumeDicomSeg, AFileWithoutExtensionIsRecognised) {
  SEGMESH_DATA_FILE(seg_file, "dcmqi/liver.dcm");
  const fs::path copy = test::scratch_dir("dicom_seg_no_extension") / "1.2.276.0.7230010";
  fs::copy_file(seg_file, copy);
  EXPECT_EQ(read_volume(copy).grid().dims, (std::array<int64_t, 3>{512, 512, 3}));
}

TEST(ReadVolumeDicomSeg, BrokenOrForeignFilesAreOneLineErrors) {
  SEGMESH_DATA_FILE(seg_file, "dcmqi/liver.dcm");
  SEGMESH_DATA_FILE(slice_file, "dcmqi/ct-3slice/01.dcm");
  const fs::path dir = test::scratch_dir("dicom_seg_broken");
  // A CT slice on its own: the series is needed.
  expect_error([&] { read_volume(slice_file); }, {slice_file.string() + ": ", "folder"});
  // Cut short inside the pixel data.
  std::vector<char> bytes = bytes_of(seg_file);
  const fs::path cut = dir / "cut.dcm";
  write_bytes(cut, std::vector<char>(bytes.begin(), bytes.end() - 1000));
  expect_error([&] { read_volume(cut); }, {cut.string() + ": broken DICOM file: truncated"});
  // Number of Frames "3 " changed to "9 ": more frames than the file describes.
  const std::string frames_element("\x28\x00\x08\x00IS\x02\x00" "3 ", 10);
  auto at = std::search(bytes.begin(), bytes.end(), frames_element.begin(), frames_element.end());
  ASSERT_NE(at, bytes.end());
  *(at + 8) = '9';
  const fs::path lying = dir / "lying.dcm";
  write_bytes(lying, bytes);
  expect_error([&] { read_volume(lying); }, {lying.string() + ": broken DICOM file", "pixel data"});
}

}  // namespace
}  // namespace segmesh
