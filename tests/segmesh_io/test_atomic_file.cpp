// AtomicFile: complete or nothing, the reason for a failed write, devices written in place.
#include "segmesh_io/atomic_file.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "segmesh/error.hpp"
#include "support/test_support.hpp"
#include "volume_test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(AtomicFile, CommitReplacesTheTargetAndAnAbandonedWriteLeavesItUntouched) {
  const fs::path dir = test::scratch_dir("atomic_file");
  const fs::path target = dir / "out.txt";
  {
    AtomicFile f(target);
    f.stream() << "first";
    EXPECT_FALSE(fs::exists(target));  // nothing under the final name before commit
    f.commit();
  }
  EXPECT_EQ(slurp(target), "first");
  {
    AtomicFile f(target);
    f.stream() << std::string(1 << 20, 'x');  // past any stream buffer: on disk, under temp_path()
    EXPECT_TRUE(fs::exists(f.temp_path()));
    EXPECT_EQ(f.temp_path().parent_path(), dir);
    EXPECT_EQ(f.temp_path().filename().string().rfind(".tmp-", 0), 0u);
  }  // destroyed without commit (an exception on the way)
  EXPECT_EQ(slurp(target), "first");
  int entries = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename(), "out.txt");
    ++entries;
  }
  EXPECT_EQ(entries, 1);
}

TEST(AtomicFile, FullDeviceReportsNoSpaceAndIsNotReplaced) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "/dev/full is not available";
  const fs::path dir = test::scratch_dir("atomic_file_full");
  fs::create_symlink("/dev/full", dir / "full.bin");
  for (size_t bytes : {size_t(10), size_t(1) << 20}) {  // failing at commit, and while writing
    AtomicFile f(dir / "full.bin");
    EXPECT_EQ(f.temp_path(), dir / "full.bin");  // a device is written in place
    f.stream() << std::string(bytes, 'x');
    try {
      f.commit();
      ADD_FAILURE() << "writing to /dev/full succeeded";
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("full.bin: cannot write (No space left on device)"), std::string::npos)
          << message;
      EXPECT_EQ(message.find('\n'), std::string::npos);
    }
  }
  EXPECT_TRUE(fs::is_symlink(dir / "full.bin"));
  EXPECT_TRUE(fs::is_character_file(dir / "full.bin"));
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

TEST(AtomicFile, MissingOrUnwritableFolderIsAnErrorBeforeWriting) {
  const fs::path dir = test::scratch_dir("atomic_file_folders");
  try {
    AtomicFile f(dir / "missing" / "out.txt");
    ADD_FAILURE() << "no error for a missing folder";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  try {
    AtomicFile f(dir);
    ADD_FAILURE() << "no error for a folder as the target";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
  if (::geteuid() != 0) {  // root writes whatever the permission bits say
    fs::create_directory(dir / "locked");
    fs::permissions(dir / "locked", fs::perms::owner_read | fs::perms::owner_exec);
    try {
      AtomicFile f(dir / "locked" / "out.txt");
      ADD_FAILURE() << "no error for a read-only folder";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("Permission denied"), std::string::npos) << e.what();
    }
    fs::permissions(dir / "locked", fs::perms::owner_all);
  }
}

}  // namespace
}  // namespace segmesh
