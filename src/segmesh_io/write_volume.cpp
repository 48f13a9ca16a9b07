#include "segmesh_io/write_volume.hpp"

#include <itkMetaImageIO.h>
#include <itkNiftiImageIO.h>
#include <itkNrrdImageIO.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/detail/volume_checks.hpp"
#include "segmesh_io/detail/volume_itk.hpp"

namespace segmesh {

namespace fs = std::filesystem;
using volume_io::file_error;

namespace {

enum class OutputFormat { nifti, nifti_gz, nrrd, metaimage };

OutputFormat output_format(const fs::path& path) {
  const std::string name = lower(path.filename().string());
  // The suffix and a name before it: ".nii" alone is not a file name to write.
  auto ends_with = [&](std::string_view suffix) {
    return name.size() > suffix.size() && name.ends_with(suffix);
  };
  if (ends_with(".nii.gz")) return OutputFormat::nifti_gz;
  if (ends_with(".nii")) return OutputFormat::nifti;
  if (ends_with(".nrrd")) return OutputFormat::nrrd;
  if (ends_with(".mha")) return OutputFormat::metaimage;
  throw file_error(path, "unknown volume format for writing; use .nii, .nii.gz, .nrrd or .mha");
}

itk::ImageIOBase::Pointer make_io(OutputFormat format) {
  switch (format) {
    case OutputFormat::nifti:
    case OutputFormat::nifti_gz:
      return itk::NiftiImageIO::New().GetPointer();
    case OutputFormat::nrrd:
      return itk::NrrdImageIO::New().GetPointer();
    case OutputFormat::metaimage:
      return itk::MetaImageIO::New().GetPointer();
  }
  return nullptr;
}

// The voxels as the smallest ITK component type that holds them all, as raw bytes.
template <class T>
std::vector<unsigned char> narrowed(const std::vector<int32_t>& voxels) {
  std::vector<unsigned char> bytes(voxels.size() * sizeof(T));
  for (size_t i = 0; i < voxels.size(); ++i) {
    const T value = static_cast<T>(voxels[i]);
    std::memcpy(bytes.data() + i * sizeof(T), &value, sizeof(T));
  }
  return bytes;
}

std::vector<unsigned char> encode(const std::vector<int32_t>& voxels, itk::IOComponentEnum& type) {
  const auto [low, high] = std::minmax_element(voxels.begin(), voxels.end());
  const int32_t min = voxels.empty() ? 0 : *low;
  const int32_t max = voxels.empty() ? 0 : *high;
  if (min >= 0 && max <= 255) {
    type = itk::IOComponentEnum::UCHAR;
    return narrowed<uint8_t>(voxels);
  }
  if (min >= -32768 && max <= 32767) {
    type = itk::IOComponentEnum::SHORT;
    return narrowed<int16_t>(voxels);
  }
  if (min >= 0 && max <= 65535) {
    type = itk::IOComponentEnum::USHORT;
    return narrowed<uint16_t>(voxels);
  }
  type = itk::IOComponentEnum::INT;
  return narrowed<int32_t>(voxels);
}

}  // namespace

void write_volume(const LabelVolume& volume, const fs::path& path) {
  const OutputFormat format = output_format(path);
  const Grid& grid = volume.grid;
  if (volume.voxels.size() != grid.voxel_count() || grid.voxel_count() == 0) {
    throw std::invalid_argument("write_volume: the volume's voxel count does not match its grid");
  }
  for (double s : grid.spacing) {
    if (!(s > 0 && std::isfinite(s)))
      throw std::invalid_argument("write_volume: spacing must be positive");
  }
  itk::IOComponentEnum component = itk::IOComponentEnum::INT;
  const std::vector<unsigned char> bytes = encode(volume.voxels, component);

  AtomicFile file(path);
  try {
    itk::ImageIOBase::Pointer io = make_io(format);
    io->SetNumberOfDimensions(3);
    io->SetPixelType(itk::IOPixelEnum::SCALAR);
    io->SetComponentType(component);
    io->SetNumberOfComponents(1);
    itk::ImageIORegion region(3);
    for (unsigned axis = 0; axis < 3; ++axis) {
      io->SetDimensions(axis, static_cast<itk::SizeValueType>(grid.dims[axis]));
      io->SetSpacing(axis, grid.spacing[axis]);
      io->SetOrigin(axis, grid.origin[axis]);
      io->SetDirection(axis, std::vector<double>{grid.direction[axis], grid.direction[3 + axis],
                                                 grid.direction[6 + axis]});
      region.SetIndex(axis, 0);
      region.SetSize(axis, static_cast<itk::SizeValueType>(grid.dims[axis]));
    }
    io->SetIORegion(region);
    io->SetUseCompression(format != OutputFormat::nifti);
    io->SetFileName(file.temp_path().string());
    io->Write(bytes.data());
  } catch (const itk::ExceptionObject& e) {
    throw volume_io::itk_error(path, "cannot write the volume", e);
  }
  file.commit();
}

}  // namespace segmesh
