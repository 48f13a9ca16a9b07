// Every input the fuzzers (fuzz/, scripts/fuzz.sh) found to crash, hang, leak or exhaust memory,
// kept as a regression test: tests/data/fuzz_regressions/<target>/<file>, where <target> names
// the fuzz target (nifti, nrrd, seg_nrrd, mha, mrc, dicom, stl, ply, obj, glb, label_names). Each
// file goes through the same call as in its fuzz target and must give a result or a one-line
// segmesh::Error within a few seconds — never another exception, a crash or a hang (the
// sanitizer build, `make sanitize`, also checks memory errors and leaks here).
// docs/ROBUSTNESS.md lists what each one found.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>

#include "segmesh/error.hpp"
#include "segmesh_io/label_names.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using volume_test::Bytes;

const std::map<std::string, std::string> kExtensions = {
    {"nifti", ".nii"}, {"nrrd", ".nrrd"}, {"seg_nrrd", ".seg.nrrd"}, {"mha", ".mha"},
    {"mrc", ".mrc"},   {"stl", ".stl"},   {"ply", ".ply"},           {"obj", ".obj"},
    {"glb", ".glb"},   {"dicom", ""},     {"label_names", ".tsv"}};

fs::path regressions_dir() {
  return fs::path(SEGMESH_SOURCE_DIR) / "tests" / "data" / "fuzz_regressions";
}

// The call of fuzz/fuzz_<target>.cpp on `bytes`; returns the Error message, or "" on success.
std::string run_reader(const std::string& target, const Bytes& bytes, const fs::path& scratch) {
  try {
    if (target == "dicom") {
      const fs::path folder = scratch / "series";
      fs::remove_all(folder);
      fs::create_directories(folder);
      if (bytes.size() >= 12 && std::memcmp(bytes.data(), "SEGMESH2", 8) == 0) {
        uint32_t first = 0;
        std::memcpy(&first, bytes.data() + 8, 4);
        const size_t n = std::min<size_t>(first, bytes.size() - 12);
        volume_test::write_bytes(folder / "a.dcm", Bytes(bytes.begin() + 12, bytes.begin() + 12 + n));
        volume_test::write_bytes(folder / "b.dcm", Bytes(bytes.begin() + 12 + n, bytes.end()));
      } else {
        volume_test::write_bytes(folder / "a.dcm", bytes);
      }
      ReadOptions options;
      options.max_voxels = 16u << 20;
      read_volume(folder, options);
      return {};
    }
    const fs::path file = scratch / ("input" + kExtensions.at(target));
    volume_test::write_bytes(file, bytes);
    if (target == "stl" || target == "ply" || target == "obj" || target == "glb") {
      read_mesh(file);
    } else if (target == "label_names") {
      read_label_names(file);
    } else {
      ReadOptions options;
      options.max_voxels = 16u << 20;
      read_volume(file, options);
    }
    return {};
  } catch (const Error& e) {
    return e.what();
  }
}

// What the fix makes of some inputs: the error must name the cause, so that the input is refused
// by our check before the library that misbehaved sees it.
const std::map<std::string, std::string> kExpected = {
    {"mha/timeout-huge-ndims", "NDims"},
    {"dicom/oom-unknown-vr-gigabyte-length", "has no valid value representation"},
    {"nifti/crash-nan-in-sform", "not finite"},
    {"dicom/oom-no-meta-group-4gb", "names no transfer syntax"},
    {"dicom/crash-gdcm-pixel-format-assert", "the pixel format is not valid"},
    {"mha/crash-long-field-name", "characters long"},
    {"mha/timeout-ndims-in-another-case", "must be spelled \"NDims\""},
    {"nifti/timeout-sform-svd-overflow", "far beyond any coordinate"},
    {"dicom/crash-gdcm-attribute-vr-assert", "where the DICOM dictionary gives DS"},
};

// The fuzzers count a run over 10 s as a hang (scripts/fuzz.sh, -timeout=10); a kept input must
// stay well clear of that, in the sanitizer build too.
constexpr double kMaxSeconds = 5;

TEST(FuzzRegressions, EveryKeptInputGivesAResultOrAOneLineError) {
  const fs::path root = regressions_dir();
  ASSERT_TRUE(fs::is_directory(root)) << root;
  const fs::path scratch = test::scratch_dir("fuzz_regressions");
  int inputs = 0;
  for (const auto& folder : fs::directory_iterator(root)) {
    if (!folder.is_directory()) continue;
    const std::string target = folder.path().filename().string();
    ASSERT_TRUE(kExtensions.count(target)) << "unknown fuzz target folder " << target;
    for (const auto& file : fs::directory_iterator(folder.path())) {
      SCOPED_TRACE(target + "/" + file.path().filename().string());
      const Bytes bytes = volume_test::read_bytes(file.path());
      std::string message;
      const auto start = std::chrono::steady_clock::now();
      ASSERT_NO_THROW(message = run_reader(target, bytes, scratch));
      const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
      EXPECT_LT(took.count(), kMaxSeconds) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      const auto expected = kExpected.find(target + "/" + file.path().filename().string());
      if (expected != kExpected.end()) {
        EXPECT_NE(message.find(expected->second), std::string::npos) << message;
      }
      ++inputs;
    }
  }
  EXPECT_GT(inputs, 0);
}

}  // namespace
}  // namespace segmesh
