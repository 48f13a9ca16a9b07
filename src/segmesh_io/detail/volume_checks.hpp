// The checks every volume reader makes before it allocates voxels, and the one-line errors they
// raise. Internal to segmesh_io.
//
// ITK (and most libraries) accept broken files quietly: a zero spacing becomes 1, a 4-D file
// yields its first volume, a truncated file reads "successfully" with missing voxels. Each reader
// therefore collects what the file claims (dimensions, spacing, how many bytes of data it holds)
// and runs it through these functions, so every format refuses the same faults with the same
// words. Messages name the file first and say what to do; `field` arguments name the header field
// at fault in the format's own terms (pixdim, ElementSpacing, space directions, ...).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "segmesh/error.hpp"
#include "segmesh/grid.hpp"
#include "segmesh_io/read_volume.hpp"

namespace segmesh::volume_io {

// Error("<path>: <what>").
Error file_error(const std::filesystem::path& path, std::string_view what);

// Passes "<path>: <what>" to options.warn, if set.
void warn(const ReadOptions& options, const std::filesystem::path& path, std::string_view what);

// "512x512x20".
std::string format_dims(std::span<const int64_t> dims);
// "0.976562 x 0.976562 x 2".
std::string format_spacing(std::span<const double> spacing);

// The three spatial dimensions of an image with dims.size() axes. Refuses 2-D images, 4-D and
// higher unless every extra axis has size 1, and any axis smaller than 1.
std::array<int64_t, 3> check_dims(const std::filesystem::path& path, std::span<const int64_t> dims);

// Refuses more than max_voxels voxels (computed without overflow).
void check_voxel_limit(const std::filesystem::path& path, const std::array<int64_t, 3>& dims,
                       uint64_t max_voxels);

// Refuses zero, negative or non-finite spacing; `field` names the header field it came from.
void check_spacing(const std::filesystem::path& path, std::span<const double> spacing,
                   std::string_view field);

// check_spacing plus a finite origin and an orthonormal direction matrix.
void check_grid(const std::filesystem::path& path, const Grid& grid,
                std::string_view spacing_field);

// Refuses a file whose data cannot hold `needed` bytes. `available` is the exact number of data
// bytes when !compressed; for compressed data it is the compressed size, and the check is the
// bound deflate can reach (about 1032:1), which catches absurd headers before anything is
// allocated (exact counts for compressed data come from inflating the stream).
void check_data_fits(const std::filesystem::path& path, uint64_t needed, uint64_t available,
                     bool compressed);

// "file is truncated (expected N bytes of image data, found M)".
Error truncated_error(const std::filesystem::path& path, uint64_t needed, uint64_t found);

// Refuses a detached data file (NRRD "data file", MetaImage ElementDataFile) that is missing or is
// not a regular file: a device such as /dev/zero never ends, and opening a named pipe waits for a
// writer forever. `header` is the file that names it.
void check_data_file(const std::filesystem::path& header, const std::filesystem::path& data);

// The detached data file `name` that `header` names (a relative name is relative to the header's
// folder), after check_data_file; unless `allow_external`, refused when it lies outside the
// header's folder (ReadOptions::allow_external_data).
std::filesystem::path detached_data_file(const std::filesystem::path& header,
                                         const std::string& name, bool allow_external);

// The error for data a header names outside its folder (or in several files) when
// ReadOptions::allow_external_data is off.
Error external_data_error(const std::filesystem::path& header, const std::string& what);

// The size of a regular file; Error naming `path` when it cannot be read.
uint64_t size_of_file(const std::filesystem::path& path);

}  // namespace segmesh::volume_io
