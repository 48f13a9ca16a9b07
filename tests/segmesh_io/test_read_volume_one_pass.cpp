// One-pass decoding of compressed volumes (detail/read_voxel_data.hpp): the fast path
// (one gzip member whose trailer agrees with the header, inflated by libdeflate into the volume
// and widened there in place) and the streaming path (everything else) must give exactly what the
// same data give uncompressed, and faults must be reported as they always were.
#include <cstring>
#include <variant>

#include "segmesh_io/read_volume.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

using volume_test::Bytes;
using volume_test::expect_error;
namespace fs = std::filesystem;

constexpr int16_t kNx = 67, kNy = 53, kNz = 41;  // 145 591 voxels: many conversion blocks
constexpr size_t kCount = size_t(kNx) * kNy * kNz;

// The voxel bytes of a volume of `size`-byte elements, from a fixed pseudo-random sequence; `make`
// turns a 32-bit random number into the element's bytes.
template <class T, class Make>
Bytes voxel_bytes(Make make) {
  Bytes bytes(kCount * sizeof(T));
  uint32_t state = 12345;
  for (size_t i = 0; i < kCount; ++i) {
    state = state * 1664525u + 1013904223u;
    const T value = make(state >> 8);
    std::memcpy(bytes.data() + i * sizeof(T), &value, sizeof(T));
  }
  return bytes;
}

Bytes nifti_file(int16_t datatype, int16_t bitpix, const Bytes& voxels, float slope = 1,
                 float intercept = 0) {
  Bytes file = volume_test::nifti1_header({kNx, kNy, kNz}, datatype, bitpix);
  volume_test::put<float>(file, 112, slope);
  volume_test::put<float>(file, 116, intercept);
  file.insert(file.end(), voxels.begin(), voxels.end());
  return file;
}

// Each test process has its own scratch file: ctest runs the tests of this file concurrently.
Bytes gzip(const Bytes& bytes) {
  static const fs::path tmp =
      test::scratch_dir("one_pass_gzip_tmp_" +
                        std::string(::testing::UnitTest::GetInstance()->current_test_info()->name())) /
      "x.gz";
  volume_test::write_gzip(tmp, bytes);
  return volume_test::read_bytes(tmp);
}

Bytes concat(Bytes a, const Bytes& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

template <class V>
void expect_same_volume(const Image& expected, const Image& actual, const std::string& what) {
  ASSERT_TRUE(std::holds_alternative<V>(actual.volume)) << what;
  const V& a = std::get<V>(expected.volume);
  const V& b = std::get<V>(actual.volume);
  EXPECT_EQ(actual.voxel_type, expected.voxel_type) << what;
  EXPECT_EQ(b.grid.dims, a.grid.dims) << what;
  ASSERT_EQ(b.voxels.size(), a.voxels.size()) << what;
  EXPECT_EQ(std::memcmp(b.voxels.data(), a.voxels.data(), a.voxels.size() * sizeof(a.voxels[0])), 0)
      << what;
}

// Every way of storing `file` compressed reads exactly like the uncompressed file.
template <class V>
void check_every_layout(const std::string& name, const Bytes& file) {
  const fs::path dir = test::scratch_dir("one_pass_" + name);
  volume_test::write_bytes(dir / "raw.nii", file);
  const Image expected = read_volume(dir / "raw.nii");
  ASSERT_TRUE(std::holds_alternative<V>(expected.volume)) << name;

  const Bytes one = gzip(file);
  const size_t cut = 352 + file.size() / 3;  // inside the voxels
  const std::vector<std::pair<std::string, Bytes>> layouts = {
      {"one_member.nii.gz", one},  // the fast path
      {"two_members.nii.gz", concat(gzip(Bytes(file.begin(), file.begin() + std::ptrdiff_t(cut))),
                                    gzip(Bytes(file.begin() + std::ptrdiff_t(cut), file.end())))},
      {"empty_last_member.nii.gz", concat(one, gzip({}))},
      {"trailing_garbage.nii.gz", concat(one, Bytes{'j', 'u', 'n', 'k', '!', '!', '!', '!'})},
      {"bytes_after_voxels.nii.gz", gzip(concat(file, Bytes(100, 7)))},
  };
  for (const auto& [file_name, bytes] : layouts) {
    volume_test::write_bytes(dir / file_name, bytes);
    expect_same_volume<V>(expected, read_volume(dir / file_name), name + " " + file_name);
  }
}

// Each integer type is stored in the narrowest of uint8, int16, uint16, int32 that holds it (the
// in-place path widens into those too); rescaled files in int32.
TEST(ReadVolumeOnePass, EveryTypeAndLayoutReadsLikeTheUncompressedFile) {
  check_every_layout<Volume<uint8_t>>(
      "uint8", nifti_file(2, 8, voxel_bytes<uint8_t>([](uint32_t r) { return uint8_t(r); })));
  check_every_layout<Volume<int16_t>>(
      "int8", nifti_file(256, 8, voxel_bytes<int8_t>([](uint32_t r) { return int8_t(r); })));
  check_every_layout<Volume<int16_t>>(
      "int16", nifti_file(4, 16, voxel_bytes<int16_t>([](uint32_t r) { return int16_t(r); })));
  check_every_layout<Volume<uint16_t>>(
      "uint16", nifti_file(512, 16, voxel_bytes<uint16_t>([](uint32_t r) { return uint16_t(r); })));
  check_every_layout<LabelVolume>(
      "int32", nifti_file(8, 32, voxel_bytes<int32_t>([](uint32_t r) { return int32_t(r * 977u); })));
  check_every_layout<LabelVolume>(
      "uint32", nifti_file(768, 32, voxel_bytes<uint32_t>([](uint32_t r) { return r; })));
  check_every_layout<LabelVolume>(
      "int64", nifti_file(1024, 64, voxel_bytes<int64_t>([](uint32_t r) { return -int64_t(r); })));
  check_every_layout<ScalarVolume>(
      "float32",
      nifti_file(16, 32, voxel_bytes<float>([](uint32_t r) { return float(r) * 1e-3f - 4e3f; })));
  check_every_layout<ScalarVolume>(
      "float64",
      nifti_file(64, 64, voxel_bytes<double>([](uint32_t r) { return double(r) * 1e-7 - 0.5; })));
  // A whole-number rescale keeps int32; a fractional one turns the volume into float part way
  // through (the first odd value), while the file bytes are still being widened in place.
  const Bytes small = voxel_bytes<int16_t>([](uint32_t r) { return int16_t((r % 4000) * 2); });
  check_every_layout<LabelVolume>("int16_whole_rescale", nifti_file(4, 16, small, 2, -1024));
  Bytes late_odd = small;
  volume_test::put<int16_t>(late_odd, late_odd.size() - 2 * 1000, 3);
  check_every_layout<ScalarVolume>("int16_fraction_rescale", nifti_file(4, 16, late_odd, 0.5f, 0));
}

TEST(ReadVolumeOnePass, LyingHeadersAndTrailersAreRefused) {
  const fs::path dir = test::scratch_dir("one_pass_liars");
  const Bytes voxels = voxel_bytes<uint8_t>([](uint32_t r) { return uint8_t(r % 3); });
  Bytes file = nifti_file(2, 8, voxels);
  volume_test::put<int16_t>(file, 46, kNz + 1);  // one slice more than the data hold
  const uint64_t claimed = kCount + uint64_t(kNx) * kNy;

  // The trailer tells the truth: refused with the exact count, found by inflating.
  Bytes honest_trailer = gzip(file);
  volume_test::write_bytes(dir / "liar.nii.gz", honest_trailer);
  expect_error([&] { read_volume(dir / "liar.nii.gz"); },
               {"liar.nii.gz: file is truncated (expected " + std::to_string(claimed) +
                " bytes of image data, found " + std::to_string(kCount) + ")"});

  // The trailer lies too (its size agrees with the header): the stream's own checks refuse it.
  Bytes lying_trailer = honest_trailer;
  volume_test::put<uint32_t>(lying_trailer, lying_trailer.size() - 4, uint32_t(352 + claimed));
  volume_test::write_bytes(dir / "both_lie.nii.gz", lying_trailer);
  expect_error([&] { read_volume(dir / "both_lie.nii.gz"); },
               {"both_lie.nii.gz: the compressed image data is corrupt"});

  // Cut inside the stream, and a damaged checksum.
  const Bytes whole = gzip(nifti_file(2, 8, voxels));
  volume_test::write_bytes(dir / "cut.nii.gz",
                           Bytes(whole.begin(), whole.begin() + std::ptrdiff_t(whole.size() / 2)));
  expect_error([&] { read_volume(dir / "cut.nii.gz"); },
               {"cut.nii.gz: file is truncated (expected " + std::to_string(kCount) +
                " bytes of image data, found "});
  Bytes bad_crc = whole;
  bad_crc[bad_crc.size() - 8] ^= 0x55;
  volume_test::write_bytes(dir / "crc.nii.gz", bad_crc);
  expect_error([&] { read_volume(dir / "crc.nii.gz"); },
               {"crc.nii.gz: the compressed image data is corrupt"});
}

TEST(ReadVolumeOnePass, StreamFaultsAndTheGridComeBeforeABadValue) {
  const fs::path dir = test::scratch_dir("one_pass_fault_order");
  Bytes voxels = voxel_bytes<uint32_t>([](uint32_t r) { return r % 100; });
  volume_test::put<uint32_t>(voxels, 40, 3'000'000'000u);  // the 11th voxel
  const Bytes file = nifti_file(768, 32, voxels);

  volume_test::write_gzip(dir / "bad_value.nii.gz", file);
  expect_error([&] { read_volume(dir / "bad_value.nii.gz"); },
               {"bad_value.nii.gz: voxel value 3000000000 does not fit"});

  // Truncated as well: the truncation is what the file is refused for.
  volume_test::write_gzip(dir / "bad_value_cut.nii.gz",
                          Bytes(file.begin(), file.end() - 1000));
  expect_error([&] { read_volume(dir / "bad_value_cut.nii.gz"); },
               {"bad_value_cut.nii.gz: file is truncated (expected " + std::to_string(4 * kCount) +
                " bytes of image data, found " + std::to_string(4 * kCount - 1000) + ")"});

  // A zero spacing as well: the header fault is reported, not the value.
  Bytes zero_spacing = file;
  volume_test::put<float>(zero_spacing, 84, 0.0f);
  volume_test::write_gzip(dir / "bad_value_spacing.nii.gz", zero_spacing);
  expect_error([&] { read_volume(dir / "bad_value_spacing.nii.gz"); }, {"voxel spacing"});
}

}  // namespace
}  // namespace segmesh
