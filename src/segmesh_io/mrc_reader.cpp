#include "segmesh_io/mrc_reader.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/data_stream.hpp"
#include "segmesh_io/detail/read_voxel_data.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

constexpr size_t header_size = 1024;
constexpr int32_t imod_stamp =
    1146047817;  // IMOD marks its files; bit 0 of its flags = signed bytes

struct MrcHeader {
  std::array<int32_t, 3> n{};  // columns, rows, sections
  int32_t mode = 0;
  std::array<int32_t, 3> start{};     // NCSTART, NRSTART, NSSTART
  std::array<int32_t, 3> sampling{};  // MX, MY, MZ
  std::array<float, 3> cell{};        // cell lengths along x, y, z
  std::array<float, 3> angles{};      // alpha, beta, gamma
  std::array<int32_t, 3> axis{};      // MAPC, MAPR, MAPS: which of x, y, z (1..3)
  int32_t nsymbt = 0;
  std::array<float, 3> origin{};
  bool imod_unsigned_bytes = false;
  bool swapped = false;
};

MrcHeader parse(const unsigned char* bytes, bool swapped) {
  MrcHeader h;
  h.swapped = swapped;
  auto i32 = [&](size_t offset) { return load_value<int32_t>(bytes + offset, swapped); };
  auto f32 = [&](size_t offset) { return load_value<float>(bytes + offset, swapped); };
  for (int a = 0; a < 3; ++a) {
    h.n[a] = i32(4 * a);
    h.start[a] = i32(16 + 4 * a);
    h.sampling[a] = i32(28 + 4 * a);
    h.cell[a] = f32(40 + 4 * a);
    h.angles[a] = f32(52 + 4 * a);
    h.axis[a] = i32(64 + 4 * a);
    h.origin[a] = f32(196 + 4 * a);
  }
  h.mode = i32(12);
  h.nsymbt = i32(92);
  h.imod_unsigned_bytes = i32(152) == imod_stamp && (i32(156) & 1) == 0;
  return h;
}

bool plausible(const MrcHeader& h) {
  const bool known_mode = h.mode >= 0 && h.mode <= 16;
  return known_mode && h.n[0] > 0 && h.n[1] > 0 && h.n[2] > 0 && h.n[0] < (1 << 24) &&
         h.n[1] < (1 << 24) && h.n[2] < (1 << 24);
}

// MACHST says the byte order; files that leave it blank get whichever order makes sense.
MrcHeader parse_header(const fs::path& path, const unsigned char* bytes) {
  const bool native_little = std::endian::native == std::endian::little;
  const unsigned char stamp = bytes[212];
  if (stamp == 0x44 || stamp == 0x41) return parse(bytes, !native_little);
  if (stamp == 0x11) return parse(bytes, native_little);
  const MrcHeader native = parse(bytes, false);
  if (plausible(native)) return native;
  const MrcHeader swapped = parse(bytes, true);
  if (plausible(swapped)) return swapped;
  throw file_error(path, "not an MRC/CCP4 map (its header makes no sense in either byte order)");
}

VoxelType voxel_type_of(const fs::path& path, const MrcHeader& h) {
  switch (h.mode) {
    case 0:
      return h.imod_unsigned_bytes ? VoxelType::uint8 : VoxelType::int8;
    case 1:
      return VoxelType::int16;
    case 2:
      return VoxelType::float32;
    case 6:
      return VoxelType::uint16;
    case 12:
      return VoxelType::float16;
    case 3:
    case 4:
      throw file_error(
          path, "complex-valued maps (mode " + std::to_string(h.mode) + ") are not supported");
    default:
      throw file_error(path, "MRC mode " + std::to_string(h.mode) +
                                 " is not supported (modes 0, 1, 2, 6 and 12 are); convert the map "
                                 "to 32-bit float (mode 2)");
  }
}

template <class T>
std::vector<T> to_xyz_order(const std::vector<T>& file_order, const std::array<int32_t, 3>& n,
                            const std::array<int32_t, 3>& axis,
                            const std::array<int64_t, 3>& dims) {
  const std::array<size_t, 3> stride{1, size_t(dims[0]), size_t(dims[0]) * size_t(dims[1])};
  const size_t sc = stride[axis[0] - 1], sr = stride[axis[1] - 1], ss = stride[axis[2] - 1];
  std::vector<T> xyz(file_order.size());
  size_t i = 0;
  for (int32_t s = 0; s < n[2]; ++s) {
    for (int32_t r = 0; r < n[1]; ++r) {
      for (int32_t c = 0; c < n[0]; ++c) xyz[c * sc + r * sr + s * ss] = file_order[i++];
    }
  }
  return xyz;
}

}  // namespace

Image read_mrc(const fs::path& path, const ReadOptions& options) {
  std::array<unsigned char, header_size> bytes{};
  uint64_t size_on_disk = size_of_file(path);
  {
    DataStream stream(path, 0, false);
    if (stream.read(bytes.data(), header_size) < header_size) {
      throw file_error(path, "not an MRC/CCP4 map (shorter than the 1024-byte header)");
    }
  }
  MrcHeader h = parse_header(path, bytes.data());
  const VoxelType type = voxel_type_of(path, h);

  if (h.axis == std::array<int32_t, 3>{0, 0, 0}) h.axis = {1, 2, 3};  // unset in some old files
  std::array<bool, 3> seen{};
  for (int32_t a : h.axis) {
    if (a < 1 || a > 3 || seen[a - 1]) {
      throw file_error(path, "MAPC/MAPR/MAPS = " + std::to_string(h.axis[0]) + "," +
                                 std::to_string(h.axis[1]) + "," + std::to_string(h.axis[2]) +
                                 " is not an ordering of 1, 2, 3; the header is corrupt");
    }
    seen[a - 1] = true;
  }
  std::array<int64_t, 3> dims{};
  std::array<int64_t, 3> start{};
  for (int f = 0; f < 3; ++f) {
    dims[h.axis[f] - 1] = h.n[f];
    start[h.axis[f] - 1] = h.start[f];
  }
  check_dims(path, dims);
  check_voxel_limit(path, dims, options.max_voxels);

  Grid grid;
  grid.dims = dims;
  for (int a = 0; a < 3; ++a) {
    grid.spacing[a] = h.sampling[a] > 0 ? double(h.cell[a]) / h.sampling[a] : 0.0;
  }
  check_spacing(path, grid.spacing, "cell length / sampling MX, MY, MZ");
  const bool has_origin = h.origin[0] != 0 || h.origin[1] != 0 || h.origin[2] != 0;
  for (int a = 0; a < 3; ++a) {
    grid.origin[a] = has_origin ? double(h.origin[a]) : double(start[a]) * grid.spacing[a];
  }
  check_grid(path, grid, "cell length / sampling MX, MY, MZ");
  const bool orthogonal = std::all_of(h.angles.begin(), h.angles.end(), [](float angle) {
    return angle == 0 || std::abs(angle - 90.0f) < 0.01f;  // 0: unset
  });
  if (!orthogonal) {
    std::ostringstream angles;
    angles << h.angles[0] << ", " << h.angles[1] << ", " << h.angles[2];
    warn(options, path,
         "the unit cell is not orthogonal (angles " + angles.str() +
             " degrees); the map is placed on perpendicular axes");
  }

  if (h.nsymbt < 0) {
    throw file_error(path, "NSYMBT " + std::to_string(h.nsymbt) +
                               " (extended header size) is negative; the header is corrupt");
  }
  const uint64_t offset = header_size + uint64_t(h.nsymbt);
  const uint64_t count = grid.voxel_count();
  const uint64_t needed = count * voxel_type_size(type);
  check_data_fits(path, needed, size_on_disk > offset ? size_on_disk - offset : 0, false);

  VoxelSink sink(path, count, type);
  read_voxel_data(path, path, offset, false, 0, count, type, h.swapped, sink);
  auto volume = std::move(sink).finish(grid);
  if (h.axis != std::array<int32_t, 3>{1, 2, 3}) {
    std::visit([&](auto& v) { v.voxels = to_xyz_order(v.voxels, h.n, h.axis, dims); }, volume);
  }
  return Image{path.string(), std::string(voxel_type_name(type)), std::move(volume), {}};
}

}  // namespace segmesh::volume_io
