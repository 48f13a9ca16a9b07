// Helpers shared by the test programs.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace segmesh::test {

// ../shared/data beside the checkout (or $SEGMESH_DATA_DIR); empty path when absent.
std::filesystem::path shared_data_dir();

// A fresh empty directory under the build tree for one test's outputs.
std::filesystem::path scratch_dir(const std::string& name);

// `path` in single quotes, for a /bin/sh command line (paths with spaces; none holds a quote).
std::string shell_quoted(const std::filesystem::path& path);

}  // namespace segmesh::test

// Skips the current test with a clear message when a file under ../shared/data is missing;
// otherwise declares `var` as its full path.
#define SEGMESH_DATA_FILE(var, relative)                                                    \
  const std::filesystem::path var = ::segmesh::test::shared_data_dir() / (relative);        \
  if (::segmesh::test::shared_data_dir().empty() || !std::filesystem::exists(var))          \
    GTEST_SKIP() << "test data " << (relative) << " not found (needs ../shared/data beside " \
                    "the checkout or SEGMESH_DATA_DIR)"
