#include "cli/cli_run.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

#include "support/test_support.hpp"

namespace segmesh::test {

namespace {
std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

CliResult run_segmesh(const std::string& args) { return run_segmesh_with_env("", args); }

CliResult run_segmesh_with_env(const std::string& environment, const std::string& args) {
  return run_segmesh_after(environment.empty() ? "" : "env " + environment, args);
}

CliResult run_segmesh_after(const std::string& shell_prefix, const std::string& args) {
  static std::atomic<int> counter{0};
  const auto dir = std::filesystem::path(SEGMESH_BINARY_DIR) / "test_scratch" / "cli_capture";
  std::filesystem::create_directories(dir);
  const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const auto out = dir / ("out_" + tag), err = dir / ("err_" + tag);
  const std::string command = (shell_prefix.empty() ? "" : shell_prefix + " ") +
                              std::string(SEGMESH_EXE) + " " + args + " >" + out.string() +
                              " 2>" + err.string();
  const int status = std::system(command.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

std::pair<int, int> png_size(const std::filesystem::path& file) {
  const std::string bytes = slurp(file);
  // Signature (8 bytes), IHDR length and type (8), then width and height, big-endian.
  if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0 || bytes.compare(12, 4, "IHDR") != 0) {
    return {0, 0};
  }
  auto be32 = [&](size_t at) {
    return int((uint8_t(bytes[at]) << 24) | (uint8_t(bytes[at + 1]) << 16) |
               (uint8_t(bytes[at + 2]) << 8) | uint8_t(bytes[at + 3]));
  };
  return {be32(16), be32(20)};
}

bool folder_holds_only(const std::filesystem::path& dir, const std::vector<std::string>& keep) {
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (std::find(keep.begin(), keep.end(), name) == keep.end()) return false;
  }
  return true;
}

}  // namespace segmesh::test
