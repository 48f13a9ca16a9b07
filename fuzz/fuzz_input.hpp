// Shared by the fuzz targets: the readers take paths, so each input is written to a file of the
// right name in this process's own scratch folder (rewritten for every input).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace segmesh::fuzz {

// $TMPDIR/segmesh-fuzz-<pid>/, created once, emptied of what a previous input left.
inline std::filesystem::path scratch_folder() {
  static const std::filesystem::path dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path d = std::filesystem::path(tmp && *tmp ? tmp : "/tmp") /
                              ("segmesh-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

// Writes `size` bytes to `folder / name` and returns the path.
inline std::filesystem::path write_file(const std::filesystem::path& folder,
                                        const std::string& name, const uint8_t* data,
                                        size_t size) {
  const std::filesystem::path path = folder / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

// A fresh empty sub-folder `name` of the scratch folder (for DICOM series).
inline std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path d = scratch_folder() / name;
  std::error_code ec;
  std::filesystem::remove_all(d, ec);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace segmesh::fuzz
