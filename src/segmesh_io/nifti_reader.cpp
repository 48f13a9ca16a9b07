#include "segmesh_io/nifti_reader.hpp"

#include <itkNiftiImageIO.h>

#include <array>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/data_stream.hpp"
#include "segmesh_io/detail/read_voxel_data.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/detail/volume_itk.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

constexpr size_t nifti1_size = 348;
constexpr size_t nifti2_size = 540;

struct NiftiHeader {
  int version = 1;
  bool swapped = false;
  std::vector<int64_t> dims;  // dim[1..dim[0]]
  int datatype = 0;
  int bitpix = 0;
  std::array<double, 8> pixdim{};
  double vox_offset = 0;
  double scl_slope = 0;
  double scl_inter = 0;
  int qform_code = 0;
  int sform_code = 0;
  std::array<double, 3> quatern{};  // b, c, d
  std::array<double, 3> qoffset{};
  double srow[3][4]{};
};

bool starts_with_gzip_magic(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  unsigned char magic[2] = {0, 0};
  file.read(reinterpret_cast<char*>(magic), 2);
  return file.gcount() == 2 && magic[0] == 0x1f && magic[1] == 0x8b;
}

// Reads field `T` at byte `offset` of the raw header.
struct HeaderBytes {
  const unsigned char* bytes;
  bool swapped;
  template <class T>
  T get(size_t offset) const {
    return load_value<T>(bytes + offset, swapped);
  }
};

// Where the fields are: NIfTI-1 and NIfTI-2 hold the same fields at other offsets, in wider types.
struct FieldOffsets {
  size_t dim, datatype, bitpix, pixdim, vox_offset, scl_slope, scl_inter, qform_code, sform_code,
      quatern, qoffset, srow;
};
constexpr FieldOffsets kNifti1Fields{40, 70, 72, 76, 108, 112, 116, 252, 254, 256, 268, 280};
constexpr FieldOffsets kNifti2Fields{16, 12, 14, 104, 168, 176, 184, 344, 348, 352, 376, 400};

// Reads the fields found `at` into `h`: dim[] as Dim, the real-valued fields as Real,
// qform_code and sform_code as Code, vox_offset as Offset (datatype and bitpix are int16 in both
// versions). Returns dim[0]; dims are read only when it is 1 to 7.
template <class Dim, class Real, class Code, class Offset>
int64_t read_fields(const HeaderBytes& b, const FieldOffsets& at, NiftiHeader& h) {
  const int64_t ndim = b.get<Dim>(at.dim);
  if (ndim >= 1 && ndim <= 7) {
    for (int64_t axis = 1; axis <= ndim; ++axis) {
      h.dims.push_back(b.get<Dim>(at.dim + sizeof(Dim) * size_t(axis)));
    }
  }
  h.datatype = b.get<int16_t>(at.datatype);
  h.bitpix = b.get<int16_t>(at.bitpix);
  for (int i = 0; i < 8; ++i) h.pixdim[i] = b.get<Real>(at.pixdim + sizeof(Real) * i);
  h.vox_offset = static_cast<double>(b.get<Offset>(at.vox_offset));
  h.scl_slope = b.get<Real>(at.scl_slope);
  h.scl_inter = b.get<Real>(at.scl_inter);
  h.qform_code = b.get<Code>(at.qform_code);
  h.sform_code = b.get<Code>(at.sform_code);
  for (int i = 0; i < 3; ++i) {
    h.quatern[i] = b.get<Real>(at.quatern + sizeof(Real) * i);
    h.qoffset[i] = b.get<Real>(at.qoffset + sizeof(Real) * i);
    for (int j = 0; j < 4; ++j) h.srow[i][j] = b.get<Real>(at.srow + sizeof(Real) * (4 * i + j));
  }
  return ndim;
}

NiftiHeader parse_header(const fs::path& path, const unsigned char* bytes, size_t size) {
  NiftiHeader h;
  const auto sizeof_hdr = load_value<int32_t>(bytes, false);
  const auto sizeof_swapped = load_value<int32_t>(bytes, true);
  if (sizeof_hdr == int32_t(nifti1_size) || sizeof_hdr == int32_t(nifti2_size)) {
    h.version = sizeof_hdr == int32_t(nifti1_size) ? 1 : 2;
  } else if (sizeof_swapped == int32_t(nifti1_size) || sizeof_swapped == int32_t(nifti2_size)) {
    h.version = sizeof_swapped == int32_t(nifti1_size) ? 1 : 2;
    h.swapped = true;
  } else {
    throw file_error(path, "not a NIfTI file (the header size field is neither 348 nor 540)");
  }
  if (size < (h.version == 1 ? nifti1_size : nifti2_size)) {
    throw file_error(path, "file is truncated (the NIfTI header is incomplete)");
  }
  const HeaderBytes b{bytes, h.swapped};
  int64_t ndim = 0;
  if (h.version == 1) {
    if (std::memcmp(bytes + 344, "ni1\0", 4) == 0) {
      throw file_error(path,
                       "is a NIfTI header whose voxels live in a separate .img file, which "
                       "is not supported; convert the pair to a single .nii.gz");
    }
    if (std::memcmp(bytes + 344, "n+1\0", 4) != 0) {
      throw file_error(path, "not a NIfTI-1 file (the magic string \"n+1\" is missing)");
    }
    ndim = read_fields<int16_t, float, int16_t, float>(b, kNifti1Fields, h);
  } else {
    if (std::memcmp(bytes + 4, "n+2\0", 4) != 0) {
      throw file_error(path, std::memcmp(bytes + 4, "ni2\0", 4) == 0
                                 ? "is a NIfTI-2 header whose voxels live in a separate file, "
                                   "which is not supported; convert it to a single .nii.gz"
                                 : "not a NIfTI-2 file (the magic string \"n+2\" is missing)");
    }
    ndim = read_fields<int64_t, double, int32_t, int64_t>(b, kNifti2Fields, h);
  }
  if (ndim < 1 || ndim > 7) {
    throw file_error(path, "the header's dim[0] is " + std::to_string(ndim) +
                               " (must be 1 to 7); the file is corrupt");
  }
  return h;
}

std::optional<VoxelType> voxel_type_of(int datatype) {
  switch (datatype) {
    case 2:
      return VoxelType::uint8;
    case 4:
      return VoxelType::int16;
    case 8:
      return VoxelType::int32;
    case 16:
      return VoxelType::float32;
    case 64:
      return VoxelType::float64;
    case 256:
      return VoxelType::int8;
    case 512:
      return VoxelType::uint16;
    case 768:
      return VoxelType::uint32;
    case 1024:
      return VoxelType::int64;
    case 1280:
      return VoxelType::uint64;
    default:
      return std::nullopt;
  }
}

std::string datatype_name(int datatype) {
  switch (datatype) {
    case 1:
      return "binary";
    case 32:
      return "complex64";
    case 128:
      return "RGB24";
    case 1536:
      return "float128";
    case 1792:
      return "complex128";
    case 2048:
      return "complex256";
    case 2304:
      return "RGBA32";
    default:
      return "unknown";
  }
}

// A NIfTI affine's columns as spacing and unit directions; false when degenerate or sheared.
bool split_affine(const double affine[3][4], Grid& grid) {
  for (int c = 0; c < 3; ++c) {
    const double length = std::sqrt(affine[0][c] * affine[0][c] + affine[1][c] * affine[1][c] +
                                    affine[2][c] * affine[2][c]);
    if (!(length > 0) || !std::isfinite(length)) return false;
    grid.spacing[c] = length;
    for (int r = 0; r < 3; ++r) grid.direction[3 * r + c] = affine[r][c] / length;
  }
  const Mat3d& m = grid.direction;
  for (int a = 0; a < 3; ++a) {
    for (int b = a + 1; b < 3; ++b) {
      if (std::abs(m[a] * m[b] + m[3 + a] * m[3 + b] + m[6 + a] * m[6 + b]) > 1e-4) return false;
    }
  }
  for (int r = 0; r < 3; ++r) grid.origin[r] = affine[r][3];
  return true;
}

// The quaternion rotation of the NIfTI standard (nifti1_io.c, quatern_to_mat44).
Mat3d quaternion_matrix(double b, double c, double d, double qfac) {
  double a = 1.0 - (b * b + c * c + d * d);
  if (a < 1e-7) {
    a = 1.0 / std::sqrt(b * b + c * c + d * d);
    b *= a;
    c *= a;
    d *= a;
    a = 0;
  } else {
    a = std::sqrt(a);
  }
  return {a * a + b * b - c * c - d * d,
          2 * (b * c - a * d),
          2 * (b * d + a * c) * qfac,
          2 * (b * c + a * d),
          a * a + c * c - b * b - d * d,
          2 * (c * d - a * b) * qfac,
          2 * (b * d - a * c),
          2 * (c * d + a * b),
          (a * a + d * d - c * c - b * b) * qfac};
}

// NIfTI-2 geometry (ITK 5.2 has no NIfTI-2 reader): the sform when set and a rotation, else the
// qform, else pixdim alone; then RAS to LPS.
Grid nifti2_grid(const NiftiHeader& h, const std::array<int64_t, 3>& dims) {
  Grid grid;
  grid.dims = dims;
  if (!(h.sform_code > 0 && split_affine(h.srow, grid))) {
    grid.spacing = {h.pixdim[1], h.pixdim[2], h.pixdim[3]};
    grid.origin = {0, 0, 0};
    grid.direction = identity3();
    if (h.qform_code > 0) {
      grid.direction =
          quaternion_matrix(h.quatern[0], h.quatern[1], h.quatern[2], h.pixdim[0] < 0 ? -1 : 1);
      grid.origin = h.qoffset;
    }
  }
  for (int c = 0; c < 3; ++c) {
    grid.direction[c] = -grid.direction[c];
    grid.direction[3 + c] = -grid.direction[3 + c];
  }
  grid.origin[0] = -grid.origin[0];
  grid.origin[1] = -grid.origin[1];
  return grid;
}

// ITK turns the qform and sform into matrices and takes their SVD in single precision (vnl;
// ITK 5.2 inverts the 4x4 sform, then its 3x3 part, to see whether it is an affine transform,
// whenever sform_code is set). vnl aborts the process on a non-finite element (found by
// fuzz_nifti: a NaN in srow_y), and LINPACK's ssvdc under vnl never converges once an element
// reaches 2^127, half the largest float: a sum of two such numbers overflows to infinity and the
// iteration goes on forever on NaN (found by fuzz_nifti: a timeout on srow_x[2] = -2^127). The
// fields ITK will use must be finite and of a size a coordinate can have; 1e15 (mm, or any unit)
// is far beyond any scanner and far below where single precision overflows.
constexpr double kMaxOrientationValue = 1e15;

void check_orientation_fields(const fs::path& path, const NiftiHeader& h) {
  std::vector<double> values{h.pixdim[0]};
  if (h.qform_code > 0) {
    values.insert(values.end(), h.quatern.begin(), h.quatern.end());
    values.insert(values.end(), h.qoffset.begin(), h.qoffset.end());
  }
  if (h.sform_code > 0) {
    for (int r = 0; r < 3; ++r) values.insert(values.end(), h.srow[r], h.srow[r] + 4);
  }
  for (const double value : values) {
    if (!std::isfinite(value)) {
      throw file_error(path,
                       "the image orientation (qform / sform) holds numbers that are not finite "
                       "(NaN or infinity); the header is corrupt");
    }
  }
  for (const double value : values) {
    if (std::abs(value) > kMaxOrientationValue) {
      std::ostringstream shown;
      shown << value;
      throw file_error(path, "the image orientation (qform / sform) holds the number " +
                                 shown.str() +
                                 ", far beyond any coordinate (at most 1e15); "
                                 "the header is corrupt");
    }
  }
}

Grid nifti1_grid_from_itk(const fs::path& path, const std::array<int64_t, 3>& dims) {
  auto io = itk::NiftiImageIO::New();
  const ItkHeader itk_header = read_itk_header(*io, path);
  if (itk_header.dims.size() < 3 || itk_header.grid.dims != dims) {
    throw file_error(path, "ITK reads the dimensions as " + format_dims(itk_header.dims) +
                               " but the header says " + format_dims(dims) +
                               "; the header is inconsistent");
  }
  return itk_header.grid;
}

}  // namespace

Image read_nifti(const fs::path& path, const ReadOptions& options) {
  const bool compressed = starts_with_gzip_magic(path);
  NiftiHeader h;
  {
    DataStream stream(path, 0, compressed);
    std::array<unsigned char, nifti2_size> bytes{};
    const size_t got = stream.read(bytes.data(), bytes.size());
    if (got < 4) throw file_error(path, "not a NIfTI file (too short)");
    h = parse_header(path, bytes.data(), got);
  }

  const std::array<int64_t, 3> dims = check_dims(path, h.dims);
  check_spacing(path, std::array{h.pixdim[1], h.pixdim[2], h.pixdim[3]}, "pixdim[1..3]");
  check_voxel_limit(path, dims, options.max_voxels);
  const std::optional<VoxelType> type = voxel_type_of(h.datatype);
  if (!type) {
    throw file_error(path, "voxel type " + datatype_name(h.datatype) + " (NIfTI datatype " +
                               std::to_string(h.datatype) +
                               ") is not supported; save the volume with an integer or float type");
  }
  if (h.bitpix != int(8 * voxel_type_size(*type))) {
    warn(options, path,
         "bitpix " + std::to_string(h.bitpix) + " does not match datatype " +
             std::string(voxel_type_name(*type)) + "; using the datatype");
  }
  const size_t header_size = h.version == 1 ? nifti1_size : nifti2_size;
  if (!(std::isfinite(h.vox_offset) && h.vox_offset >= double(header_size) &&
        h.vox_offset == std::floor(h.vox_offset) && h.vox_offset < 1e15)) {
    throw file_error(path, "vox_offset " + std::to_string(h.vox_offset) +
                               " is not a valid data position; the file is corrupt");
  }
  const auto vox_offset = static_cast<uint64_t>(h.vox_offset);
  const uint64_t count = uint64_t(dims[0]) * uint64_t(dims[1]) * uint64_t(dims[2]);
  const uint64_t needed = count * voxel_type_size(*type);

  // Absurd sizes are refused before anything is allocated: raw data against the file's size,
  // compressed data against the best ratio deflate can reach. The exact count of compressed data
  // comes from inflating it, once: straight into the volume when the gzip trailer agrees with
  // the header (touching memory only then), else block by block into storage that grows with
  // the data, so a lying header costs no more memory than the data the file really holds.
  const uint64_t size_on_disk = size_of_file(path);
  if (compressed) {
    check_data_fits(path, vox_offset + needed, size_on_disk, true);
  } else {
    check_data_fits(path, needed, size_on_disk > vox_offset ? size_on_disk - vox_offset : 0, false);
  }

  Rescale rescale;
  if (std::isfinite(h.scl_slope) && h.scl_slope != 0) {  // slope 0 means "no scaling"
    rescale.slope = h.scl_slope;
    rescale.intercept = std::isfinite(h.scl_inter) ? h.scl_inter : 0;
  }
  VoxelSink sink(path, count, *type, rescale);
  sink.defer_value_errors();
  // Faults are reported in the order they always were: a truncated or corrupt stream, then the
  // grid, then a voxel value outside int32 (deferred to finish()).
  read_voxel_data(path, path, compressed ? 0 : vox_offset, compressed, compressed ? vox_offset : 0,
                  count, *type, h.swapped, sink);

  check_orientation_fields(path, h);
  const Grid grid = h.version == 1 ? nifti1_grid_from_itk(path, dims) : nifti2_grid(h, dims);
  check_grid(path, grid, "pixdim[1..3] / sform");

  return Image{
      path.string(), std::string(voxel_type_name(*type)), std::move(sink).finish(grid), {}};
}

}  // namespace segmesh::volume_io
