#include "cli_common.hpp"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <sstream>

#include "segmesh/error.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::cli {

void add_read_options(CLI::App* cmd, ReadArgs& args) {
  cmd->add_option("--max-voxels", args.max_voxels,
                  "refuse volumes with more voxels than this, before allocating (memory guard)")
      ->capture_default_str()
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            uint64_t count = 0;
            const auto [end, ec] = std::from_chars(value.data(), value.data() + value.size(), count);
            if (ec != std::errc() || end != value.data() + value.size() || count == 0) {
              return "must be a whole number of voxels, at least 1 (got \"" + value + "\")";
            }
            return {};
          },
          "COUNT"));
}

Image read_input(const std::filesystem::path& path, const ReadArgs& args) {
  if (args.max_voxels == 0) throw Error("--max-voxels must be at least 1");
  ReadOptions options;
  options.max_voxels = args.max_voxels;
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

}  // namespace segmesh::cli
