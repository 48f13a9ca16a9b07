// DICOM folders that are broken in the ways copies from scanners, PACS exports and USB sticks are
// (issue 7): a slice cut short anywhere (in its meta header, its data set or its pixel data), an
// empty slice, a slice out of place (uneven spacing), slices missing at the ends or in the middle,
// and foreign files (text, binary, another series) among the slices. A broken slice is an Error
// naming the file; a gap is an Error; foreign files are skipped with a warning. GDCM alone aborts
// the process on some of these and reads others with missing pixels.
#include <algorithm>

#include "segmesh_io/detail/dicom_file_check.hpp"
#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::Bytes;
using volume_test::expect_error;
namespace fs = std::filesystem;

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

// A writable copy of the 93-slice head CT (CTHead1.dcm .. CTHead93.dcm, 1.5 mm apart).
fs::path copy_series(const fs::path& source, const std::string& name) {
  const fs::path folder = test::scratch_dir(name);
  for (const auto& entry : fs::directory_iterator(source)) {
    fs::copy_file(entry.path(), folder / entry.path().filename());
    fs::permissions(folder / entry.path().filename(), fs::perms::owner_read | fs::perms::owner_write);
  }
  return folder;
}

TEST(ReadVolumeDicomRobustness, TruncatedSliceIsAnErrorNamingTheFile) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  // Cut in the pixel data (by 2 bytes and by half), in the data set, in the meta header, inside
  // the preamble, and to nothing; in the middle of the series and at both ends.
  for (const char* slice : {"CTHead50.dcm", "CTHead1.dcm", "CTHead93.dcm"}) {
    const uintmax_t full = fs::file_size(dir / slice);
    for (uintmax_t size : {full - 2, full / 2, uintmax_t(600), uintmax_t(200), uintmax_t(100),
                           uintmax_t(0)}) {
      SCOPED_TRACE(std::string(slice) + " cut to " + std::to_string(size) + " bytes");
      const fs::path folder = copy_series(dir, "dicom_truncated");
      fs::resize_file(folder / slice, size);
      const std::string message =
          expect_error([&] { read_volume(folder); }, {(folder / slice).string() + ": "});
      const bool says_why = message.find("truncated") != std::string::npos ||
                            message.find("not one") != std::string::npos;
      EXPECT_TRUE(says_why) << message;
    }
  }
  // The check on its own: the intact slice is an image.
  EXPECT_EQ(volume_io::check_dicom_file(dir / "CTHead50.dcm").status,
            volume_io::DicomFileStatus::image);
}

TEST(ReadVolumeDicomRobustness, SliceOutOfPlaceOrMissingIsAnError) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  // CTHead50 moved from z = 73.5 to 74.0 mm (ImagePositionPatient, same length): gaps of 2 and
  // 1 mm where the others are 1.5.
  fs::path folder = copy_series(dir, "dicom_uneven");
  Bytes bytes = volume_test::read_bytes(folder / "CTHead50.dcm");
  const std::string from = "0\\0\\73.5", to = "0\\0\\74.0";
  const auto at = std::search(bytes.begin(), bytes.end(), from.begin(), from.end());
  ASSERT_NE(at, bytes.end());
  std::copy(to.begin(), to.end(), at);
  volume_test::write_bytes(folder / "CTHead50.dcm", bytes);
  expect_error([&] { read_volume(folder); },
               {folder.string() + ": the slices are not evenly spaced: 2 mm between CTHead49.dcm "
                                  "and CTHead50.dcm where the others are 1.5 mm apart",
                "1 more uneven gap"});

  // Two neighbouring slices missing.
  folder = copy_series(dir, "dicom_two_missing");
  fs::remove(folder / "CTHead20.dcm");
  fs::remove(folder / "CTHead21.dcm");
  expect_error([&] { read_volume(folder); },
               {"4.5 mm between CTHead19.dcm and CTHead22.dcm", "a slice is probably missing"});

  // Slices missing at the ends cannot be told from a shorter scan: a regular, shorter volume.
  folder = copy_series(dir, "dicom_ends_missing");
  fs::remove(folder / "CTHead1.dcm");
  fs::remove(folder / "CTHead93.dcm");
  EXPECT_EQ(read_volume(folder).grid().dims, (std::array<int64_t, 3>{64, 64, 91}));
}

TEST(ReadVolumeDicomRobustness, ForeignFilesAreSkippedWithAWarning) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  SEGMESH_DATA_FILE(other, "dcmqi/ct-3slice/01.dcm");
  SEGMESH_DATA_FILE(seg, "dcmqi/liver.dcm");
  const fs::path folder = copy_series(dir, "dicom_foreign_files");
  volume_test::write_text(folder / "README.txt", "exported by some PACS\n");
  volume_test::write_bytes(folder / "thumbs.db", Bytes(3000, 0xAB));
  volume_test::write_bytes(folder / "DICOMDIR", Bytes(10, 0));  // an empty-looking index
  volume_test::write_text(folder / ".DS_Store", "");
  fs::copy_file(other, folder / "other_series.dcm");
  fs::copy_file(seg, folder / "segmentation.dcm");
  Warnings warnings;
  const Image image = read_volume(folder, warnings.options());
  EXPECT_EQ(image.grid().dims, (std::array<int64_t, 3>{64, 64, 93}));
  for (const char* name : {"README.txt", "thumbs.db", "DICOMDIR", ".DS_Store"}) {
    EXPECT_TRUE(warnings.any_contains("skipping " + std::string(name) + ": not a DICOM file"))
        << name;
  }
  EXPECT_TRUE(warnings.any_contains("skipping segmentation.dcm: a multi-frame object"));
  EXPECT_TRUE(warnings.any_contains("holds 2 series"));
  for (const std::string& w : warnings.messages) {
    EXPECT_EQ(w.find('\n'), std::string::npos) << w;
  }
}

TEST(ReadVolumeDicomRobustness, FileNamedDicomThatIsNotIsAnError) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  const fs::path folder = copy_series(dir, "dicom_fake_dcm");
  volume_test::write_text(folder / "CTHead94.dcm", "<html>404 not found</html>");
  expect_error([&] { read_volume(folder); },
               {(folder / "CTHead94.dcm").string() + ": is named like a DICOM file but is not one"});
}

// GDCM reads ImagePositionPatient as a typed DS attribute and asserts (aborts) when the file
// labels it otherwise (fuzz_dicom: "CS"). Every element must carry its dictionary VR.
TEST(ReadVolumeDicomRobustness, ElementWithTheWrongValueRepresentationIsAnError) {
  SEGMESH_DATA_FILE(dir, "slicer_ct_head/CTHeadAxialDicom");
  const fs::path folder = copy_series(dir, "dicom_wrong_vr");
  Bytes bytes = volume_test::read_bytes(folder / "CTHead50.dcm");
  const std::string from("\x20\x00\x32\x00" "DS", 6);
  const auto at = std::search(bytes.begin(), bytes.end(), from.begin(), from.end());
  ASSERT_NE(at, bytes.end());
  at[4] = 'C';
  volume_test::write_bytes(folder / "CTHead50.dcm", bytes);
  expect_error([&] { read_volume(folder); },
               {(folder / "CTHead50.dcm").string() +
                ": is a broken DICOM file (element (0020,0032) has the value representation CS "
                "where the DICOM dictionary gives DS); replace it"});
  // Every slice of the real series carries its dictionary VRs.
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(volume_io::check_dicom_file(entry.path()).status, volume_io::DicomFileStatus::image)
        << entry.path();
  }
}

TEST(ReadVolumeDicomRobustness, StructuralCheckOnHandMadeFiles) {
  const fs::path folder = test::scratch_dir("dicom_check");
  // A Part 10 file whose meta group claims more than the file holds.
  Bytes bytes(128, 0);
  volume_test::append(bytes, "DICM");
  volume_test::append(bytes, std::string("\x02\x00\x10\x00UI\xff\x00", 8));
  volume_test::append(bytes, "1.2.840.10008.1.2");
  volume_test::write_bytes(folder / "meta.dcm", bytes);
  auto check = volume_io::check_dicom_file(folder / "meta.dcm");
  EXPECT_EQ(check.status, volume_io::DicomFileStatus::broken) << check.reason;
  // Sequences nested 40 deep (undefined lengths) are refused, not recursed into.
  Bytes deep(128, 0);
  volume_test::append(deep, "DICM");
  volume_test::append(deep, std::string("\x02\x00\x10\x00UI\x14\x00", 8));
  volume_test::append(deep, std::string("1.2.840.10008.1.2.1\0", 20));  // explicit VR LE
  for (int i = 0; i < 40; ++i) {
    volume_test::append(deep, std::string("\x08\x00\x15\x11SQ\x00\x00\xff\xff\xff\xff", 12));
    volume_test::append(deep, std::string("\xfe\xff\x00\xe0\xff\xff\xff\xff", 8));
  }
  volume_test::write_bytes(folder / "deep.dcm", deep);
  check = volume_io::check_dicom_file(folder / "deep.dcm");
  EXPECT_EQ(check.status, volume_io::DicomFileStatus::broken);
  EXPECT_NE(check.reason.find("32 deep"), std::string::npos) << check.reason;
  // A Part 10 file without its file meta group (no transfer syntax): GDCM would guess.
  Bytes bare(128, 0);
  volume_test::append(bare, "DICM");
  volume_test::append(bare, std::string("\x08\x00\x60\x00" "CS\x02\x00" "CT", 10));
  volume_test::write_bytes(folder / "bare.dcm", bare);
  check = volume_io::check_dicom_file(folder / "bare.dcm");
  EXPECT_EQ(check.status, volume_io::DicomFileStatus::broken);
  EXPECT_NE(check.reason.find("transfer syntax"), std::string::npos) << check.reason;
  // Text is not DICOM.
  volume_test::write_text(folder / "a.txt", "hello");
  EXPECT_EQ(volume_io::check_dicom_file(folder / "a.txt").status,
            volume_io::DicomFileStatus::not_dicom);
}

}  // namespace
}  // namespace segmesh
