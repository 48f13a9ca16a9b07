#include "support/test_support.hpp"

#include <cstdlib>

namespace segmesh::test {

std::filesystem::path shared_data_dir() {
  if (const char* env = std::getenv("SEGMESH_DATA_DIR"); env && *env) {
    return std::filesystem::exists(env) ? std::filesystem::path(env) : std::filesystem::path();
  }
  const auto dir = std::filesystem::path(SEGMESH_SOURCE_DIR).parent_path() / "shared" / "data";
  return std::filesystem::exists(dir) ? dir : std::filesystem::path();
}

std::filesystem::path scratch_dir(const std::string& name) {
  const auto dir = std::filesystem::path(SEGMESH_BINARY_DIR) / "test_scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string shell_quoted(const std::filesystem::path& path) {
  std::string quoted = path.string();  // (not "'" + ... + "'": GCC 12 warns falsely about it)
  quoted.insert(quoted.begin(), '\'');
  quoted.push_back('\'');
  return quoted;
}

}  // namespace segmesh::test
