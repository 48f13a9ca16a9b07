// MappedFile (mapped_file.hpp): the bytes from an offset to the end of a regular file; an empty
// view for an empty file or an offset past the end; not opened, with the errno, for a missing
// file or one that is not regular.
#include <gtest/gtest.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <string>

#include "segmesh_io/detail/mapped_file.hpp"
#include "support/test_support.hpp"

namespace segmesh::volume_io {
namespace {

namespace fs = std::filesystem;

void write_file(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(MappedFile, ViewsTheBytesFromTheOffset) {
  const fs::path dir = test::scratch_dir("mapped_file_view");
  write_file(dir / "a.bin", "0123456789");
  const MappedFile whole(dir / "a.bin");
  ASSERT_TRUE(whole.opened());
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(whole.data()), whole.size()), "0123456789");
  const MappedFile tail(dir / "a.bin", 7);
  ASSERT_TRUE(tail.opened());
  tail.advise_sequential();
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(tail.data()), tail.size()), "789");
  for (const uint64_t offset : {uint64_t(10), uint64_t(11)}) {
    const MappedFile past(dir / "a.bin", offset);
    EXPECT_TRUE(past.opened());
    EXPECT_EQ(past.data(), nullptr);
    EXPECT_EQ(past.size(), 0u);
  }
  write_file(dir / "empty.bin", "");
  const MappedFile empty(dir / "empty.bin");
  EXPECT_TRUE(empty.opened());
  EXPECT_EQ(empty.size(), 0u);
}

TEST(MappedFile, MissingOrNotRegularIsNotOpened) {
  const fs::path dir = test::scratch_dir("mapped_file_errors");
  const MappedFile missing(dir / "missing.bin");
  EXPECT_FALSE(missing.opened());
  EXPECT_EQ(missing.error(), ENOENT);
  const MappedFile folder(dir);
  EXPECT_FALSE(folder.opened());
  EXPECT_EQ(folder.error(), EINVAL);
  EXPECT_EQ(folder.data(), nullptr);
}

}  // namespace
}  // namespace segmesh::volume_io
