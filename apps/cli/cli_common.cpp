#include "cli_common.hpp"

#include <chrono>
#include <cstdio>
#include <sstream>

#include "segmesh/error.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::cli {

Image read_input(const std::filesystem::path& path) {
  ReadOptions options;
  options.warn = [](const std::string& message) {
    std::fprintf(stderr, "segmesh: warning: %s\n", message.c_str());
  };
  return read_volume(path, options);
}

std::unique_ptr<tbb::global_control> limit_threads(int threads) {
  if (threads < 0) throw Error("--threads must be 0 (all cores) or more");
  if (threads == 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<size_t>(threads));
}

template <class T>
std::array<T, 3> parse_triple(const std::string& text, const std::string& option) {
  std::array<T, 3> out{};
  std::istringstream in(text);
  for (int a = 0; a < 3; ++a) {
    if (!(in >> out[a]) || (a < 2 && in.get() != ',')) {
      throw Error(option + " expects three comma-separated numbers like 512,512,203 (got \"" +
                  text + "\")");
    }
  }
  if (in.peek() != std::char_traits<char>::eof()) {
    throw Error(option + " expects exactly three numbers (got \"" + text + "\")");
  }
  return out;
}

template std::array<int64_t, 3> parse_triple(const std::string&, const std::string&);
template std::array<double, 3> parse_triple(const std::string&, const std::string&);

nlohmann::json grid_json(const Grid& grid) {
  return {{"dims", grid.dims},
          {"spacing", grid.spacing},
          {"origin", grid.origin},
          {"direction", grid.direction}};
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace segmesh::cli
