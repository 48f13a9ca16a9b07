// Robustness of the segmesh command line (issue 7): headers that lie about their size, the voxel
// limit (--max-voxels) on every command that reads a volume, outputs that would overwrite the
// input, folders that cannot be written, a full device, and a writer killed mid-way.
// Every bad case must give exit code 2, one line on stderr and no output file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include "cli/cli_run.hpp"
#include "segmesh/volume.hpp"
#include "segmesh_io/volume_test_support.hpp"
#include "segmesh_io/write_volume.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using test::run_segmesh;
using volume_test::Bytes;

std::string q(const fs::path& p) {
  std::string quoted = p.string();
  quoted.insert(quoted.begin(), '\'');
  quoted.push_back('\'');
  return quoted;
}

// A 12^3 label map with a 6^3 cube of label 1.
fs::path write_cube(const fs::path& dir, const std::string& name) {
  LabelVolume volume;
  volume.grid.dims = {12, 12, 12};
  volume.voxels.assign(12 * 12 * 12, 0);
  for (int z = 3; z < 9; ++z)
    for (int y = 3; y < 9; ++y)
      for (int x = 3; x < 9; ++x) volume.at(x, y, z) = 1;
  write_volume(volume, dir / name);
  return dir / name;
}

void expect_one_line_error(const test::CliResult& r, const std::string& what,
                           const std::string& fragment) {
  EXPECT_EQ(r.exit_code, 2) << what << ": " << r.err;
  EXPECT_EQ(r.err.rfind("segmesh: error: ", 0), 0u) << what << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << ": " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << what << ": " << r.err;
}

// An MRC header (1024 bytes) for nx x ny x nz int8 voxels of 1 unit, followed by `data` bytes.
Bytes mrc_file(int32_t nx, int32_t ny, int32_t nz, size_t data) {
  // Sized once (a resize from 1024 trips a false -Warray-bounds in GCC 12's vector).
  Bytes b(1024 + data, 7);
  std::fill(b.begin(), b.begin() + 1024, 0);
  volume_test::put<int32_t>(b, 0, nx);
  volume_test::put<int32_t>(b, 4, ny);
  volume_test::put<int32_t>(b, 8, nz);
  volume_test::put<int32_t>(b, 12, 0);  // mode 0: int8
  volume_test::put<int32_t>(b, 28, nx);
  volume_test::put<int32_t>(b, 32, ny);
  volume_test::put<int32_t>(b, 36, nz);
  volume_test::put<float>(b, 40, float(nx));
  volume_test::put<float>(b, 44, float(ny));
  volume_test::put<float>(b, 48, float(nz));
  for (int i = 0; i < 3; ++i) volume_test::put<float>(b, 52 + 4 * i, 90.0f);
  for (int i = 0; i < 3; ++i) volume_test::put<int32_t>(b, 64 + 4 * i, i + 1);
  std::memcpy(b.data() + 208, "MAP ", 4);
  b[212] = 0x44;
  b[213] = 0x44;
  return b;
}

// segmesh's memory is capped for the lying-header runs: by the address space (ulimit -v) in a
// normal build; AddressSanitizer reserves terabytes of address space for its shadow memory, so a
// sanitizer build caps single allocations instead (an allocation over the cap throws bad_alloc,
// which segmesh reports as "out of memory").
#if defined(__SANITIZE_ADDRESS__)
#define SEGMESH_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SEGMESH_TEST_ASAN 1
#endif
#endif
#ifdef SEGMESH_TEST_ASAN
const char* const kMemoryCap =
    "ASAN_OPTIONS=\"$ASAN_OPTIONS:max_allocation_size_mb=1500:allocator_may_return_null=1\"";
#else
const char* const kMemoryCap = "ulimit -v 1500000;";
#endif

// Headers claiming 2000 x 2000 x 400 voxels (1.6e9: under the default limit, 6.4 GB as int32)
// in files of a few kilobytes, in every format. segmesh runs with its memory capped at 1.5 GB
// (kMemoryCap), so a reader that allocated before checking the file would fail with "out of
// memory" instead of naming the lie.
TEST(CliRobustness, LyingHeadersAreRefusedBeforeAllocating) {
  const fs::path dir = test::scratch_dir("cli_lying_headers");
  Bytes nifti = volume_test::nifti1_header({2000, 2000, 400}, 2, 8);
  nifti.resize(5000, 1);
  volume_test::write_bytes(dir / "liar.nii", nifti);
  volume_test::write_gzip(dir / "liar.nii.gz", nifti);
  Bytes nrrd;
  volume_test::append(nrrd,
                      "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2000 2000 400\n"
                      "spacings: 1 1 1\nencoding: raw\n\n");
  nrrd.resize(nrrd.size() + 4000, 1);
  volume_test::write_bytes(dir / "liar.nrrd", nrrd);
  Bytes nrrd_gz;
  volume_test::append(nrrd_gz,
                      "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2000 2000 400\n"
                      "spacings: 1 1 1\nencoding: gzip\n\n");
  volume_test::write_gzip(dir / "payload.gz", Bytes(4000, 1));
  const Bytes payload = volume_test::read_bytes(dir / "payload.gz");
  fs::remove(dir / "payload.gz");
  nrrd_gz.insert(nrrd_gz.end(), payload.begin(), payload.end());
  volume_test::write_bytes(dir / "liar_gz.nrrd", nrrd_gz);
  Bytes mha;
  volume_test::append(mha,
                      "ObjectType = Image\nNDims = 3\nDimSize = 2000 2000 400\n"
                      "ElementType = MET_UCHAR\nElementSpacing = 1 1 1\nElementDataFile = LOCAL\n");
  mha.resize(mha.size() + 4000, 1);
  volume_test::write_bytes(dir / "liar.mha", mha);
  volume_test::write_bytes(dir / "liar.mrc", mrc_file(2000, 2000, 400, 4000));

  for (const char* name :
       {"liar.nii", "liar.nii.gz", "liar.nrrd", "liar_gz.nrrd", "liar.mha", "liar.mrc"}) {
    for (const std::string& command : {std::string("info"), std::string("mesh")}) {
      const std::string args = command + " " + q(dir / name) +
                               (command == "mesh" ? " -o " + q(dir / "out.glb") : std::string());
      const auto r = test::run_segmesh_after(kMemoryCap, args);
      const std::string what = command + " " + name;
      expect_one_line_error(r, what, name);
      EXPECT_EQ(r.err.find("memory"), std::string::npos) << what << ": " << r.err;
      const bool names_the_lie = r.err.find("truncated") != std::string::npos ||
                                 r.err.find("cannot hold") != std::string::npos;
      EXPECT_TRUE(names_the_lie) << what << ": " << r.err;
      EXPECT_FALSE(fs::exists(dir / "out.glb")) << what;
    }
  }
  // Over the limit: refused from the header alone, whatever the file holds.
  Bytes huge = volume_test::nifti1_header({30000, 30000, 30000}, 2, 8);
  volume_test::write_bytes(dir / "huge.nii", huge);
  const auto r = test::run_segmesh_after(kMemoryCap, "info " + q(dir / "huge.nii"));
  expect_one_line_error(r, "huge", "30000x30000x30000 = 2.7e+13 voxels exceeds the limit");
}

// --max-voxels on every command that reads a volume; the default admits 1024^3.
TEST(CliRobustness, MaxVoxelsOnEveryCommandThatReadsAVolume) {
  const fs::path dir = test::scratch_dir("cli_max_voxels");
  const fs::path cube = write_cube(dir, "cube.nii");  // 12^3 = 1728 voxels
  const std::vector<std::pair<std::string, std::string>> commands = {
      {"info", "info " + q(cube)},
      {"mesh", "mesh " + q(cube) + " -o " + q(dir / "out.ply") + " --quiet"},
      {"render", "render " + q(cube) + " -o " + q(dir / "out.png") + " --size 64,48 --quiet"},
      {"study", "study " + q(cube) + " -o " + q(dir / "study") + " --quiet"},
  };
  for (const auto& [name, args] : commands) {
    const auto r = run_segmesh(args + " --max-voxels 1727");
    if (name == "render" && (r.err.find("OpenGL") != std::string::npos ||
                             r.err.find("EGL") != std::string::npos)) {
      continue;  // no headless OpenGL here; the render tests say so
    }
    expect_one_line_error(r, name, "12x12x12 = 1.73e+03 voxels exceeds the limit of 1727 voxels");
    EXPECT_NE(r.err.find("--max-voxels"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(dir / "out.ply"));
  EXPECT_FALSE(fs::exists(dir / "out.png"));
  EXPECT_FALSE(fs::exists(dir / "study" / "study.md"));
  // Exactly at the limit is fine.
  auto r = run_segmesh("info " + q(cube) + " --max-voxels 1728");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  r = run_segmesh("mesh " + q(cube) + " -o " + q(dir / "out.ply") + " --quiet --max-voxels 1728");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out.ply"));
  // Values that are not a positive count.
  for (const char* bad : {"0", "-5", "lots"}) {
    r = run_segmesh("info " + q(cube) + " --max-voxels " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--max-voxels"), std::string::npos) << bad << ": " << r.err;
  }
  // The default admits a 1024^3 volume: a header of 1024^3 voxels in a short file is refused
  // for being truncated, not for its size.
  Bytes nifti = volume_test::nifti1_header({1024, 1024, 1024}, 2, 8);
  volume_test::write_bytes(dir / "gig.nii", nifti);
  r = run_segmesh("info " + q(dir / "gig.nii"));
  expect_one_line_error(r, "1024^3", "file is truncated (expected 1073741824 bytes");
  r = run_segmesh("info " + q(dir / "gig.nii") + " --max-voxels 1000000");
  expect_one_line_error(r, "1024^3 over a lowered limit", "exceeds the limit of 1000000 voxels");
}

// Inputs that are not regular files: a named pipe (opening it would wait for a writer forever),
// detached data files that are a device (never ending), a pipe or a folder. Each is refused at
// once; the test's own timeout (ctest) catches a hang.
TEST(CliRobustness, PipesAndDevicesAreRefusedNotWaitedOn) {
  const fs::path dir = test::scratch_dir("cli_special_files");
  ASSERT_EQ(::mkfifo((dir / "pipe.nii").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "pipe.raw").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "pipe.stl").c_str(), 0600), 0);
  const std::string nrrd = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nspacings: 1 1 1\n";
  volume_test::write_text(dir / "zero.nhdr", nrrd + "encoding: raw\ndata file: /dev/zero\n\n");
  volume_test::write_text(dir / "random.nhdr", nrrd + "encoding: gzip\ndata file: /dev/urandom\n\n");
  volume_test::write_text(dir / "pipe.nhdr", nrrd + "encoding: raw\ndata file: pipe.raw\n\n");
  volume_test::write_text(dir / "folder.nhdr", nrrd + "encoding: raw\ndata file: .\n\n");
  volume_test::write_text(dir / "zero.mhd",
                          "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
                          "ElementSpacing = 1 1 1\nElementDataFile = /dev/zero\n");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"info " + q(dir / "pipe.nii"), "is not a regular file"},
      {"info " + q(dir / "zero.nhdr"), "its data file /dev/zero is not a regular file"},
      {"info " + q(dir / "random.nhdr"), "its data file /dev/urandom is not a regular file"},
      {"info " + q(dir / "pipe.nhdr"), "pipe.raw is not a regular file"},
      {"info " + q(dir / "folder.nhdr"), "is not a regular file"},
      {"info " + q(dir / "zero.mhd"), "its data file /dev/zero is not a regular file"},
      {"quality " + q(dir / "pipe.stl"), "pipe.stl: "},
  };
  for (const auto& [args, fragment] : cases) {
    // `timeout` turns a hang into exit 124 instead of stalling the suite.
    const auto r = test::run_segmesh_after("timeout 60", args);
    expect_one_line_error(r, args, fragment);
  }
}

// -o (or --report) naming the input, directly or through another path, link or hard link.
TEST(CliRobustness, OutputThatIsTheInputIsRefused) {
  const fs::path dir = test::scratch_dir("cli_overwrite_input");
  const fs::path cube = write_cube(dir, "cube.nii");
  const Bytes original = volume_test::read_bytes(cube);
  fs::create_hard_link(cube, dir / "hard.glb");
  fs::create_symlink(cube, dir / "soft.ply");
  fs::create_directory(dir / "sub");
  const std::string other = q(dir / "sub" / ".." / "cube.nii");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"hard link", "mesh " + q(cube) + " -o " + q(dir / "hard.glb")},
      {"symbolic link", "mesh " + q(cube) + " -o " + q(dir / "soft.ply")},
      {"other spelling, hard link", "mesh " + other + " -o " + q(dir / "hard.glb")},
      {"report", "mesh " + q(cube) + " -o " + q(dir / "out.glb") + " --report " + other},
      {"render", "render " + q(cube) + " -o " + q(dir / "hard.png")},
  };
  fs::create_hard_link(cube, dir / "hard.png");
  for (const auto& [what, args] : cases) {
    const auto r = run_segmesh(args + " --quiet");
    expect_one_line_error(r, what, "is the input; choose another output path");
    EXPECT_EQ(volume_test::read_bytes(cube), original) << what;
    EXPECT_FALSE(fs::exists(dir / "out.glb")) << what;
  }
  EXPECT_TRUE(fs::is_symlink(dir / "soft.ply"));
  EXPECT_TRUE(test::folder_holds_only(dir, {"cube.nii", "hard.glb", "soft.ply", "hard.png", "sub"}));
}

TEST(CliRobustness, ReadOnlyFolderIsReportedBeforeMeshing) {
  // Root writes whatever the permission bits say; as root the commands run as the unprivileged
  // user "nobody" (uid 65534) through setpriv, and the case is skipped when that is impossible.
  std::string as_user;
  if (::geteuid() == 0) {
    if (std::system("setpriv --reuid=65534 --regid=65534 --clear-groups true 2>/dev/null") != 0) {
      GTEST_SKIP() << "running as root, where permission bits do not stop writes, and setpriv "
                      "cannot drop to an unprivileged user here";
    }
    as_user = "setpriv --reuid=65534 --regid=65534 --clear-groups";
  }
  const fs::path dir = test::scratch_dir("cli_read_only");
  const fs::path cube = write_cube(dir, "cube.nii");
  fs::create_directory(dir / "locked");
  fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
  for (const std::string& args :
       {"mesh " + q(cube) + " -o " + q(dir / "locked" / "out.glb"),
        "mesh " + q(cube) + " -o " + q(dir / "locked" / "parts") + "/",
        "mesh " + q(cube) + " -o " + q(dir / "out.glb") + " --report " +
            q(dir / "locked" / "r.json"),
        "phantom -o " + q(dir / "locked" / "p.nii") + " --size 8,8,8"}) {
    const auto r = test::run_segmesh_after(as_user, args + " --quiet");
    expect_one_line_error(r, args, "Permission denied");
  }
  fs::permissions(dir / "locked", fs::perms::owner_all);
  EXPECT_TRUE(fs::is_empty(dir / "locked"));
  EXPECT_FALSE(fs::exists(dir / "out.glb"));
}

// Unreadable inputs (permission denied). Root reads whatever the permission bits say; as root the
// commands run as the unprivileged user "nobody" (uid 65534) through setpriv, as in
// ReadOnlyFolderIsReportedBeforeMeshing. Empty when the commands can run as they are; nullopt
// when running as root and setpriv cannot drop privileges.
std::optional<std::string> unprivileged_prefix() {
  if (::geteuid() != 0) return std::string();
  if (std::system("setpriv --reuid=65534 --regid=65534 --clear-groups true 2>/dev/null") != 0) {
    return std::nullopt;
  }
  return std::string("setpriv --reuid=65534 --regid=65534 --clear-groups");
}

const char* const kNoUnprivilegedUser =
    "running as root, where permission bits do not stop reads, and setpriv cannot drop to an "
    "unprivileged user here";

// A command on an input that cannot be read: the unreadable file, and the file given when that is
// another one (the header whose data file is locked, the DICOM folder whose slice is locked).
struct UnreadableCase {
  std::string what, args;
  fs::path unreadable, given = {};
};

// Every case: exit code 2, one line "segmesh: error: <file>: ..." beginning with the unreadable (or
// the given) file, naming the unreadable one and saying it is a permission problem; nothing on
// stdout and no output in `dir` (which anyone may write, so a missing output is segmesh's refusal),
// whose only files are `inputs`.
void expect_unreadable_refused(const std::string& as_user, const fs::path& dir,
                               const std::vector<std::string>& inputs,
                               const std::vector<UnreadableCase>& cases) {
  for (const UnreadableCase& c : cases) {
    const auto r = test::run_segmesh_after(as_user, c.args);
    if (c.what.rfind("render", 0) == 0 &&
        (r.err.find("OpenGL") != std::string::npos || r.err.find("EGL") != std::string::npos)) {
      continue;  // no headless OpenGL here; the render tests say so
    }
    EXPECT_EQ(r.exit_code, 2) << c.what << ": " << r.err;
    const bool begins_with_the_file =
        r.err.rfind("segmesh: error: " + c.unreadable.string() + ": ", 0) == 0 ||
        (!c.given.empty() && r.err.rfind("segmesh: error: " + c.given.string() + ": ", 0) == 0);
    EXPECT_TRUE(begins_with_the_file)
        << c.what << ": not \"segmesh: error: <file>: ...\": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find(c.unreadable.filename().string()), std::string::npos)
        << c.what << ": the message should name " << c.unreadable.filename() << ": " << r.err;
    EXPECT_NE(r.err.find("ermission"), std::string::npos)
        << c.what << ": the message should say the file may not be read: " << r.err;
    EXPECT_TRUE(r.out.empty()) << c.what << ": " << r.out;
    EXPECT_TRUE(test::folder_holds_only(dir, inputs)) << c.what << ": an output was written";
    for (const auto& entry : fs::directory_iterator(dir)) {  // judge every case on its own
      const std::string name = entry.path().filename().string();
      if (std::find(inputs.begin(), inputs.end(), name) == inputs.end())
        fs::remove_all(entry.path());
    }
  }
}

// Gives the owner back every permission, so the scratch folder can be removed by anyone.
void unlock_all(const fs::path& dir) {
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    fs::permissions(entry.path(), fs::perms::owner_all, fs::perm_options::add);
  }
}

// Volume files of every format, mesh files, a --label-names table and a folder nobody may read,
// through every command that reads them.
TEST(CliRobustness, UnreadableInputIsReportedWithoutOutput) {
  const auto as_user = unprivileged_prefix();
  if (!as_user) GTEST_SKIP() << kNoUnprivilegedUser;
  const fs::path dir = test::scratch_dir("cli_unreadable");
  fs::permissions(dir, fs::perms::all);
  const fs::path cube = write_cube(dir, "cube.nii");
  const std::vector<std::string> meshes = {"cube.stl", "cube.ply", "cube.obj", "cube.glb"};
  for (const std::string& name : meshes) {
    const auto r = run_segmesh("mesh " + q(cube) + " -o " + q(dir / name) + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << name << ": " << r.err;
  }
  std::vector<std::string> volumes = {"locked.nii", "locked.nii.gz", "locked.nrrd", "locked.mha"};
  for (const std::string& name : volumes) write_cube(dir, name);
  volume_test::write_bytes(dir / "locked.mrc", mrc_file(12, 12, 12, 12 * 12 * 12));
  volumes.push_back("locked.mrc");
  volume_test::write_text(dir / "labels.tsv", "1\tcube\tbone\n");
  fs::create_directory(dir / "unlisted");  // a folder (DICOM series) that cannot be listed
  write_cube(dir / "unlisted", "slice.nii");

  std::vector<UnreadableCase> cases;
  for (const std::string& name : volumes) {
    const fs::path in = dir / name;
    cases.push_back({"info " + name, "info " + q(in), in});
    cases.push_back(
        {"mesh " + name, "mesh " + q(in) + " -o " + q(dir / "out.glb") + " --quiet", in});
    cases.push_back({"mesh " + name + " into a folder",
                     "mesh " + q(in) + " -o " + q(dir / "parts") + "/ --quiet", in});
    cases.push_back({"mesh " + name + " with a report",
                     "mesh " + q(in) + " -o " + q(dir / "out.ply") + " --report " +
                         q(dir / "r.json") + " --quiet",
                     in});
    cases.push_back(
        {"render " + name, "render " + q(in) + " -o " + q(dir / "out.png") + " --quiet", in});
    cases.push_back(
        {"study " + name, "study " + q(in) + " -o " + q(dir / "study") + " --quiet", in});
  }
  for (const std::string& name : meshes) {
    cases.push_back({"quality " + name, "quality " + q(dir / name), dir / name});
    cases.push_back({"render " + name,
                     "render " + q(dir / name) + " -o " + q(dir / "out.png") + " --quiet",
                     dir / name});
  }
  cases.push_back(
      {"info of a folder that cannot be listed", "info " + q(dir / "unlisted"), dir / "unlisted"});
  cases.push_back({"mesh with an unreadable --label-names",
                   "mesh " + q(cube) + " -o " + q(dir / "out.glb") + " --label-names " +
                       q(dir / "labels.tsv") + " --quiet",
                   dir / "labels.tsv"});
  std::vector<std::string> inputs = {"cube.nii", "cube.mtl", "labels.tsv", "unlisted"};
  inputs.insert(inputs.end(), meshes.begin(), meshes.end());
  inputs.insert(inputs.end(), volumes.begin(), volumes.end());
  for (const std::string& name : inputs) {
    if (name != "cube.nii" && name != "cube.mtl") fs::permissions(dir / name, fs::perms::none);
  }
  expect_unreadable_refused(*as_user, dir, inputs, cases);
  unlock_all(dir);
}

// Readable headers (NRRD .nhdr, MetaImage .mhd) whose detached data file nobody may read.
TEST(CliRobustness, UnreadableDetachedDataFileIsReportedWithoutOutput) {
  const auto as_user = unprivileged_prefix();
  if (!as_user) GTEST_SKIP() << kNoUnprivilegedUser;
  const fs::path dir = test::scratch_dir("cli_unreadable_detached");
  fs::permissions(dir, fs::perms::all);
  volume_test::write_bytes(dir / "data.raw", Bytes(64, 1));
  volume_test::write_text(dir / "detached.nhdr",
                          "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nspacings: 1 1 1\n"
                          "encoding: raw\ndata file: data.raw\n\n");
  volume_test::write_text(
      dir / "detached.mhd",
      "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
      "ElementSpacing = 1 1 1\nElementDataFile = data.raw\n");
  std::vector<UnreadableCase> cases;
  for (const char* name : {"detached.nhdr", "detached.mhd"}) {
    const fs::path header = dir / name;
    cases.push_back({std::string("info ") + name, "info " + q(header), dir / "data.raw", header});
    cases.push_back({std::string("mesh ") + name,
                     "mesh " + q(header) + " -o " + q(dir / "out.glb") + " --quiet",
                     dir / "data.raw", header});
  }
  fs::permissions(dir / "data.raw", fs::perms::none);
  expect_unreadable_refused(*as_user, dir, {"data.raw", "detached.nhdr", "detached.mhd"}, cases);
  unlock_all(dir);
}

// A DICOM series with one slice nobody may read must be an error, not a series without that
// slice: slices named *.dcm, and without an extension (as scanners write them), the locked slice
// being the first of the series, where no spacing check notices a missing slice.
TEST(CliRobustness, UnreadableDicomSliceIsReportedWithoutOutput) {
  SEGMESH_DATA_FILE(head, "slicer_ct_head/CTHeadAxialDicom");
  const auto as_user = unprivileged_prefix();
  if (!as_user) GTEST_SKIP() << kNoUnprivilegedUser;
  const fs::path dir = test::scratch_dir("cli_unreadable_dicom");
  fs::permissions(dir, fs::perms::all);
  for (const char* series : {"series", "series_plain"}) {
    fs::create_directory(dir / series);
    for (const auto& entry : fs::directory_iterator(head)) {
      const fs::path copy =
          dir / series /
          (std::string(series) == "series" ? entry.path().filename() : entry.path().stem());
      fs::copy_file(entry.path(), copy);
      fs::permissions(copy, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                                fs::perms::others_read);
    }
  }
  const fs::path dcm = dir / "series" / "CTHead40.dcm", plain = dir / "series_plain" / "CTHead1";
  ASSERT_TRUE(fs::exists(dcm) && fs::exists(plain));
  const std::vector<UnreadableCase> cases = {
      {"info of a series with an unreadable slice", "info " + q(dir / "series"), dcm,
       dir / "series"},
      {"mesh of a series with an unreadable slice",
       "mesh " + q(dir / "series") + " -o " + q(dir / "out.glb") + " --iso 1150 --quiet", dcm,
       dir / "series"},
      {"info of a series (no extensions) with an unreadable first slice",
       "info " + q(dir / "series_plain"), plain, dir / "series_plain"},
      {"mesh of a series (no extensions) with an unreadable first slice",
       "mesh " + q(dir / "series_plain") + " -o " + q(dir / "out.glb") + " --iso 1150 --quiet",
       plain, dir / "series_plain"},
  };
  fs::permissions(dcm, fs::perms::none);
  fs::permissions(plain, fs::perms::none);
  expect_unreadable_refused(*as_user, dir, {"series", "series_plain"}, cases);
  unlock_all(dir);
}

// /dev/full fails every write with ENOSPC, like a full disk. The output (a link to it) must not
// be replaced by a regular file, and the error must say why.
TEST(CliRobustness, FullDeviceGivesNoSpaceLeftOnDevice) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "/dev/full is not available";
  const fs::path dir = test::scratch_dir("cli_dev_full");
  const fs::path cube = write_cube(dir, "cube.nii");
  fs::create_symlink("/dev/full", dir / "full.glb");
  fs::create_symlink("/dev/full", dir / "full.stl");
  fs::create_symlink("/dev/full", dir / "full.json");
  for (const std::string& args :
       {"mesh " + q(cube) + " -o " + q(dir / "full.glb"),
        "mesh " + q(cube) + " -o " + q(dir / "full.stl"),
        "mesh " + q(cube) + " -o " + q(dir / "out.ply") + " --report " + q(dir / "full.json")}) {
    const auto r = run_segmesh(args + " --quiet");
    EXPECT_NE(r.exit_code, 0) << args;
    expect_one_line_error(r, args, "No space left on device");
  }
  for (const char* name : {"full.glb", "full.stl", "full.json"}) {
    EXPECT_TRUE(fs::is_symlink(dir / name)) << name;
    EXPECT_TRUE(fs::is_character_file(dir / name)) << name;
  }
  // The mesh itself was written (a complete file) before the report failed; nothing else is
  // left over.
  EXPECT_TRUE(test::folder_holds_only(dir, {"cube.nii", "full.glb", "full.stl", "full.json",
                                            "out.ply"}));
}

// segmesh mesh killed (SIGKILL) at several moments, among them while the output is being
// written: the output is always the previous complete file, or (a kill after the rename, while
// the run prints its summary) the new complete one — never a partial file.
TEST(CliRobustness, KilledWriterLeavesThePreviousFile) {
  const fs::path dir = test::scratch_dir("cli_kill");
  const fs::path big = dir / "big.nii";
  auto r = run_segmesh("phantom -o " + q(big));  // 512 x 512 x 203
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const fs::path cube = write_cube(dir, "cube.nii");
  const fs::path out = dir / "out.glb";
  r = run_segmesh("mesh " + q(cube) + " -o " + q(out) + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Bytes previous = volume_test::read_bytes(out);
  ASSERT_GT(previous.size(), 100u);
  // What an uninterrupted run writes (the output does not depend on timing or threads).
  fs::create_directory(dir / "ref");
  r = run_segmesh("mesh " + q(big) + " -o " + q(dir / "ref" / "out.glb") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Bytes complete = volume_test::read_bytes(dir / "ref" / "out.glb");

  const auto temp_exists = [&](pid_t pid) {
    const std::string prefix = ".tmp-" + std::to_string(pid) + "-";
    for (const auto& entry : fs::directory_iterator(dir)) {
      if (entry.path().filename().string().rfind(prefix, 0) == 0) return true;
    }
    return false;
  };
  int killed_while_writing = 0;
  // Kill after fixed delays (reading, meshing), then as soon as the temporary file appears.
  // The GLB is written in some 10-100 ms, so a kill on sight of the temporary file can miss it
  // on a loaded machine: up to eight tries, until two kills have landed mid-write.
  const std::vector<int> delays = {100, 250, 500, -1, -1, -1, -1, -1, -1, -1, -1};
  for (int delay_ms : delays) {
    if (delay_ms < 0 && killed_while_writing >= 2) break;
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(null, 1);
      ::dup2(null, 2);
      ::execl(SEGMESH_EXE, SEGMESH_EXE, "mesh", big.c_str(), "-o", out.c_str(), "--quiet",
              static_cast<char*>(nullptr));
      ::_exit(127);
    }
    const auto start = std::chrono::steady_clock::now();
    bool writing = false;
    int status = 0;
    bool exited = false;
    for (;;) {
      if (::waitpid(pid, &status, WNOHANG) == pid) {
        exited = true;
        break;
      }
      writing = temp_exists(pid);
      const auto elapsed = std::chrono::steady_clock::now() - start;
      if ((delay_ms < 0 && writing) ||
          (delay_ms >= 0 && elapsed >= std::chrono::milliseconds(delay_ms))) {
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
    if (!exited) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
    }
    if (WIFEXITED(status)) {
      // Finished before the kill: the output must then be the new, complete file.
      EXPECT_EQ(WEXITSTATUS(status), 0);
      EXPECT_TRUE(volume_test::read_bytes(out) == complete);
      r = run_segmesh("mesh " + q(cube) + " -o " + q(out) + " --quiet");  // restore
      ASSERT_EQ(r.exit_code, 0);
      continue;
    }
    ASSERT_TRUE(WIFSIGNALED(status));
    const Bytes now = volume_test::read_bytes(out);
    if (now == complete) {  // killed after the rename: the new file, complete
      r = run_segmesh("mesh " + q(cube) + " -o " + q(out) + " --quiet");  // restore
      ASSERT_EQ(r.exit_code, 0);
    } else {
      EXPECT_EQ(now, previous) << "killed after " << delay_ms << " ms: a partial output";
      if (writing) ++killed_while_writing;
    }
    // What a killed run leaves is a hidden temporary name, never the final one; remove it.
    for (const auto& entry : fs::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      if (name == "big.nii" || name == "cube.nii" || name == "out.glb" || name == "ref") continue;
      EXPECT_EQ(name.rfind(".tmp-" + std::to_string(pid) + "-", 0), 0u) << name;
      fs::remove(entry.path());
    }
  }
  EXPECT_GE(killed_while_writing, 1) << "no kill landed while the output was being written";
  r = run_segmesh("quality " + q(out));
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// A DICOM folder with a slice cut short: exit 2, one line naming the slice (GDCM's own multi-line
// warnings silenced), no output; a foreign file beside the slices: one warning line, and meshed.
TEST(CliRobustness, DicomFolderWithATruncatedSliceOrAForeignFile) {
  SEGMESH_DATA_FILE(head, "slicer_ct_head/CTHeadAxialDicom");
  const fs::path dir = test::scratch_dir("cli_dicom_truncated");
  const fs::path folder = dir / "series";
  fs::create_directory(folder);
  for (const auto& entry : fs::directory_iterator(head)) {
    fs::copy_file(entry.path(), folder / entry.path().filename());
    fs::permissions(folder / entry.path().filename(), fs::perms::owner_read | fs::perms::owner_write);
  }
  volume_test::write_text(folder / "notes.txt", "scanned 2009\n");
  auto r = run_segmesh("mesh " + q(folder) + " -o " + q(dir / "skull.ply") + " --iso 1150 --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err, "segmesh: warning: " + folder.string() + ": skipping notes.txt: not a DICOM file\n");
  fs::remove(dir / "skull.ply");
  for (uintmax_t size : {uintmax_t(5000), uintmax_t(600)}) {
    fs::resize_file(folder / "CTHead40.dcm", size);
    r = run_segmesh("mesh " + q(folder) + " -o " + q(dir / "skull.ply") + " --iso 1150 --quiet");
    // Files are scanned in name order: a warning about notes.txt may precede the error.
    const size_t last = r.err.rfind("segmesh: error: ");
    ASSERT_NE(last, std::string::npos) << r.err;
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find((folder / "CTHead40.dcm").string() + ": is a broken DICOM file (truncated",
                         last),
              std::string::npos)
        << r.err;
    // Nothing else: every line is segmesh's own (GDCM's multi-line warnings are silenced).
    std::istringstream lines(r.err);
    int errors = 0;
    for (std::string line; std::getline(lines, line);) {
      EXPECT_TRUE(line.rfind("segmesh: warning: ", 0) == 0 || line.rfind("segmesh: error: ", 0) == 0)
          << line;
      errors += line.rfind("segmesh: error: ", 0) == 0;
    }
    EXPECT_EQ(errors, 1) << r.err;
    EXPECT_FALSE(fs::exists(dir / "skull.ply"));
  }
}

}  // namespace
}  // namespace segmesh
