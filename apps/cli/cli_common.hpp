// Pieces the subcommands share: reading the input with warnings on stderr, thread limits,
// parsing "X,Y,Z" triples, and the JSON form of a grid.
#pragma once

#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "segmesh/grid.hpp"
#include "segmesh/image.hpp"
#include "segmesh_io/mesh_report.hpp"

namespace segmesh::cli {

// The voxel limit of every command that reads a volume (ReadOptions::max_voxels): the default
// (2e9) admits a 1024^3 volume; a header claiming more is refused before anything is allocated.
struct ReadArgs {
  uint64_t max_voxels = 2'000'000'000;
};

// Adds --max-voxels to `cmd`.
void add_read_options(CLI::App* cmd, ReadArgs& args);

// Reads a volume; the reader's warnings go to stderr as "segmesh: warning: ...".
Image read_input(const std::filesystem::path& path, const ReadArgs& args = {});

// Limits the worker threads for the lifetime of the returned object (0: all cores).
std::unique_ptr<tbb::global_control> limit_threads(int threads);

// Parses "a,b,c" into three numbers; throws segmesh::Error naming `option` otherwise.
template <class T>
std::array<T, 3> parse_triple(const std::string& text, const std::string& option);

nlohmann::json grid_json(const Grid& grid);

using segmesh::ms_since;  // milliseconds since a start (segmesh_io/mesh_report.hpp)

}  // namespace segmesh::cli
