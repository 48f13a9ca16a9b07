#include "segmesh_io/read_volume.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <new>
#include <string>

#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/dicom_seg_reader.hpp"
#include "segmesh_io/dicom_series.hpp"
#include "segmesh_io/metaimage_reader.hpp"
#include "segmesh_io/mrc_reader.hpp"
#include "segmesh_io/nifti_reader.hpp"
#include "segmesh_io/nrrd_reader.hpp"

namespace segmesh {

namespace fs = std::filesystem;
using volume_io::file_error;

namespace {

enum class Format { nifti, nrrd, metaimage, mrc, dicom, dicom_file, unknown };

// The extensions read_volume reads, a longer one before any it ends with.
struct Suffix {
  const char* text;
  Format format;
};
constexpr Suffix kSuffixes[] = {{".nii.gz", Format::nifti},    {".nii", Format::nifti},
                                {".seg.nrrd", Format::nrrd},   {".nrrd", Format::nrrd},
                                {".nhdr", Format::nrrd},       {".mha", Format::metaimage},
                                {".mhd", Format::metaimage},   {".mrc", Format::mrc},
                                {".map", Format::mrc},         {".rec", Format::mrc}};

Format format_of(const fs::path& path) {
  const std::string name = lower(path.filename().string());
  for (const Suffix& s : kSuffixes) {
    if (name.ends_with(s.text)) return s.format;
  }
  if (name.ends_with(".dcm") || name.ends_with(".dicom") || name.ends_with(".ima")) {
    return Format::dicom_file;
  }
  // DICOM files often have no extension: the "DICM" magic after the 128-byte preamble (looked
  // for in regular files only: opening a named pipe would block).
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Format::unknown;
  std::ifstream in(path, std::ios::binary);
  char magic[132] = {};
  if (in.read(magic, sizeof magic) && std::string_view(magic + 128, 4) == "DICM") {
    return Format::dicom_file;
  }
  return Format::unknown;
}

}  // namespace

std::string volume_extension(const fs::path& path) {
  const std::string name = lower(path.filename().string());
  for (const Suffix& s : kSuffixes) {
    if (name.ends_with(s.text) && name.size() > std::string_view(s.text).size()) return s.text;
  }
  return {};
}

Image read_volume(const fs::path& path, const ReadOptions& options) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw file_error(path, "no such file");
  const Format format = fs::is_directory(status) ? Format::dicom : format_of(path);
  if (format == Format::unknown) {
    throw file_error(path,
                     "unknown volume format; expected .nii, .nii.gz, .nrrd, .nhdr, "
                     ".seg.nrrd, .mha, .mhd, .mrc, .map, .rec, a DICOM SEG file or a DICOM "
                     "folder");
  }
  if (format != Format::dicom) {
    // Opening a named pipe blocks until something writes to it; a device never ends. The readers
    // need a regular file (they check its size and read it more than once).
    if (!fs::is_regular_file(status)) {
      throw file_error(path, "is not a regular file (a device, pipe or socket); give a volume "
                             "file or a DICOM folder");
    }
    if (!std::ifstream(path, std::ios::binary)) {
      throw file_error(path, std::string("cannot open the file (") + std::strerror(errno) + ")");
    }
    if (volume_io::size_of_file(path) == 0) throw file_error(path, "file is empty");
  }

  try {
    switch (format) {
      case Format::nifti:
        return volume_io::read_nifti(path, options);
      case Format::nrrd:
        return volume_io::read_nrrd(path, options);
      case Format::metaimage:
        return volume_io::read_metaimage(path, options);
      case Format::mrc:
        return volume_io::read_mrc(path, options);
      case Format::dicom:
        return volume_io::read_dicom_series(path, options);
      case Format::dicom_file:
        // One file is a volume only as a DICOM SEG object; a slice needs its series.
        return volume_io::read_dicom_seg(path, options);
      case Format::unknown:
        break;
    }
  } catch (const std::bad_alloc&) {
    throw file_error(path,
                     "not enough memory to hold the volume; lower the resolution or crop it first");
  }
  throw file_error(path, "unknown volume format");
}

std::array<int64_t, 3> check_volume_geometry(const std::string& name,
                                             std::span<const int64_t> dims, const Grid& grid,
                                             const ReadOptions& options) {
  const std::array<int64_t, 3> three = volume_io::check_dims(name, dims);
  volume_io::check_voxel_limit(name, three, options.max_voxels);
  volume_io::check_grid(name, grid, "spacing");
  return three;
}

}  // namespace segmesh
