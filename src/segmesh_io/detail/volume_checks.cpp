#include "segmesh_io/detail/volume_checks.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <sstream>
#include <system_error>

namespace segmesh::volume_io {

namespace fs = std::filesystem;

Error file_error(const fs::path& path, std::string_view what) {
  return Error(path.string() + ": " + std::string(what));
}

void warn(const ReadOptions& options, const fs::path& path, std::string_view what) {
  if (options.warn) options.warn(path.string() + ": " + std::string(what));
}

std::string format_dims(std::span<const int64_t> dims) {
  std::string text;
  for (size_t i = 0; i < dims.size(); ++i) {
    if (i > 0) text += 'x';
    text += std::to_string(dims[i]);
  }
  return text;
}

std::string format_spacing(std::span<const double> spacing) {
  std::ostringstream text;
  for (size_t i = 0; i < spacing.size(); ++i) {
    if (i > 0) text << " x ";
    text << spacing[i];
  }
  return text.str();
}

std::array<int64_t, 3> check_dims(const fs::path& path, std::span<const int64_t> dims) {
  const std::string shown = format_dims(dims);
  if (dims.size() < 3) {
    throw file_error(path, std::to_string(dims.size()) + "-D images are not supported (dims " +
                               shown + "); segmesh needs a 3-D volume");
  }
  for (int64_t d : dims) {
    if (d < 1) {
      throw file_error(path, "the header gives an invalid image size " + shown +
                                 " (every dimension must be at least 1); the file is corrupt");
    }
  }
  for (size_t axis = 3; axis < dims.size(); ++axis) {
    if (dims[axis] != 1) {
      throw file_error(path, std::to_string(dims.size()) + "-D images are not supported (dims " +
                                 shown + "); extract one volume first");
    }
  }
  return {dims[0], dims[1], dims[2]};
}

void check_voxel_limit(const fs::path& path, const std::array<int64_t, 3>& dims,
                       uint64_t max_voxels) {
  // Doubles cannot overflow here and are exact far beyond any limit we compare with.
  const double voxels = double(dims[0]) * double(dims[1]) * double(dims[2]);
  if (voxels > double(max_voxels)) {
    std::ostringstream count;
    count.precision(3);
    count << voxels;
    throw file_error(path, format_dims(dims) + " = " + count.str() +
                               " voxels exceeds the limit of " + std::to_string(max_voxels) +
                               " voxels; crop or downsample the volume, or raise the limit "
                               "(segmesh --max-voxels) if the memory is there");
  }
}

void check_spacing(const fs::path& path, std::span<const double> spacing, std::string_view field) {
  for (double s : spacing) {
    if (!(std::isfinite(s) && s > 0)) {
      throw file_error(path, "voxel spacing " + format_spacing(spacing) + " is not valid (" +
                                 std::string(field) +
                                 " must be positive and finite); fix the file's header");
    }
  }
}

void check_grid(const fs::path& path, const Grid& grid, std::string_view spacing_field) {
  check_spacing(path, grid.spacing, spacing_field);
  for (double o : grid.origin) {
    if (!std::isfinite(o))
      throw file_error(path, "the image origin is not a finite number; fix the file's header");
  }
  // Columns must be unit length and mutually perpendicular; 1e-3 tolerates single-precision
  // headers (NIfTI stores the orientation as float).
  const Mat3d& m = grid.direction;
  for (int a = 0; a < 3; ++a) {
    for (int b = a; b < 3; ++b) {
      const double d = m[a] * m[b] + m[3 + a] * m[3 + b] + m[6 + a] * m[6 + b];
      const double expected = a == b ? 1.0 : 0.0;
      if (!(std::abs(d - expected) < 1e-3)) {
        throw file_error(path,
                         "the image orientation (direction matrix) is not a rotation or "
                         "mirroring (axes are sheared or degenerate); fix the file's header");
      }
    }
  }
}

void check_data_fits(const fs::path& path, uint64_t needed, uint64_t available, bool compressed) {
  if (!compressed) {
    if (available < needed) throw truncated_error(path, needed, available);
    return;
  }
  // Deflate's best case is 258 bytes from about 2 bits: 1032:1.
  constexpr double max_ratio = 1032;
  if (double(available) * max_ratio + 1024 < double(needed)) {
    throw file_error(path,
                     "file is truncated or its header is wrong: " + std::to_string(available) +
                         " bytes of compressed data cannot hold the " + std::to_string(needed) +
                         " bytes the header claims");
  }
}

Error truncated_error(const fs::path& path, uint64_t needed, uint64_t found) {
  return file_error(path, "file is truncated (expected " + std::to_string(needed) +
                              " bytes of image data, found " + std::to_string(found) + ")");
}

void check_data_file(const fs::path& header, const fs::path& data) {
  std::error_code ec;
  const fs::file_status status = fs::status(data, ec);
  if (!fs::exists(status)) {
    throw file_error(header, "its data file " + data.string() + " does not exist");
  }
  if (!fs::is_regular_file(status)) {
    throw file_error(header, "its data file " + data.string() +
                                 " is not a regular file (a folder, device or pipe); the header "
                                 "must name the file holding the voxels");
  }
  // Readable: otherwise the library that opens it next reports a header problem instead.
  const int fd = ::open(data.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw file_error(data, std::string("cannot open the file (") + std::strerror(errno) + ")");
  ::close(fd);
}

Error external_data_error(const fs::path& header, const std::string& what) {
  return file_error(header, what + "; pass --allow-external-data to read it anyway");
}

fs::path detached_data_file(const fs::path& header, const std::string& name, bool allow_external) {
  fs::path data = name;
  if (data.is_relative()) data = header.parent_path() / data;
  if (!allow_external) {
    // Both resolved (symbolic links and ".." included), then the folder must be a prefix.
    std::error_code e1, e2;
    const fs::path folder = fs::weakly_canonical(fs::absolute(header).parent_path(), e1);
    const fs::path target = fs::weakly_canonical(fs::absolute(data), e2);
    const auto [f, t] = std::mismatch(folder.begin(), folder.end(), target.begin(), target.end());
    if (e1 || e2 || f != folder.end()) {
      throw external_data_error(header, "its data file \"" + name + "\" lies outside its folder");
    }
  }
  check_data_file(header, data);
  return data;
}

uint64_t size_of_file(const fs::path& path) {
  std::error_code ec;
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) throw file_error(path, "cannot read the file (" + ec.message() + ")");
  return size;
}

}  // namespace segmesh::volume_io
