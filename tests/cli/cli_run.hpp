// Runs the segmesh executable from a test and captures its exit code, stdout and stderr.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace segmesh::test {

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

// Runs `segmesh <args>` (args are passed to /bin/sh, so quote paths with spaces).
CliResult run_segmesh(const std::string& args);

// The same with environment variables set for the run: `environment` is "NAME=value ...".
CliResult run_segmesh_with_env(const std::string& environment, const std::string& args);

// The same run preceded, in the same shell, by `shell_prefix` (e.g. "ulimit -v 1000000;").
CliResult run_segmesh_after(const std::string& shell_prefix, const std::string& args);

// Width and height from a PNG file's header; {0, 0} when the file is not a PNG.
std::pair<int, int> png_size(const std::filesystem::path& file);

// True when `dir` holds no regular file other than those named in `keep`.
bool folder_holds_only(const std::filesystem::path& dir, const std::vector<std::string>& keep);

}  // namespace segmesh::test
