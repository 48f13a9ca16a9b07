#include "segmesh_io/detail/volume_itk.hpp"

#include <itkImageIOBase.h>

#include <sstream>

#include "segmesh_io/detail/text.hpp"
#include "segmesh_io/detail/volume_checks.hpp"

namespace segmesh::volume_io {

namespace fs = std::filesystem;

namespace {

// ITK's descriptions span several lines and start with the class and object address
// ("ITK ERROR: NrrdImageIO(0x5648b9343600): Read: ..."); teem's add "[nrrd] function: ".
// The last meaningful line without those prefixes is what a user can read.
std::string short_reason(const std::exception& e) {
  std::string text = e.what();
  if (const auto* itk_exception = dynamic_cast<const itk::ExceptionObject*>(&e)) {
    text = itk_exception->GetDescription();
  }
  std::string reason;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    line = std::string(trim(line));
    if (!line.empty()) reason = line;
  }
  if (!reason.empty() && reason.front() == '[') {
    if (const auto end = reason.find("] "); end != std::string::npos) reason.erase(0, end + 2);
    if (const auto colon = reason.find(": "); colon != std::string::npos)
      reason.erase(0, colon + 2);
  }
  if (const auto address = reason.find("): ");
      address != std::string::npos && reason.find("ERROR") != std::string::npos) {
    reason.erase(0, address + 3);
  }
  return reason.empty() ? std::string("unknown ITK error") : reason;
}

}  // namespace

Error itk_error(const fs::path& path, std::string_view context, const std::exception& e) {
  return file_error(path, std::string(context) + " (" + short_reason(e) + ")");
}

std::optional<VoxelType> voxel_type_from_itk(int component) {
  using C = itk::IOComponentEnum;
  switch (static_cast<C>(component)) {
    case C::UCHAR:
      return VoxelType::uint8;
    case C::CHAR:
      return VoxelType::int8;
    case C::USHORT:
      return VoxelType::uint16;
    case C::SHORT:
      return VoxelType::int16;
    case C::UINT:
      return VoxelType::uint32;
    case C::INT:
      return VoxelType::int32;
    case C::ULONG:
      return sizeof(unsigned long) == 8 ? VoxelType::uint64 : VoxelType::uint32;
    case C::LONG:
      return sizeof(long) == 8 ? VoxelType::int64 : VoxelType::int32;
    case C::ULONGLONG:
      return VoxelType::uint64;
    case C::LONGLONG:
      return VoxelType::int64;
    case C::FLOAT:
      return VoxelType::float32;
    case C::DOUBLE:
      return VoxelType::float64;
    default:
      return std::nullopt;
  }
}

ItkHeader read_itk_header(itk::ImageIOBase& io, const fs::path& path) {
  ItkHeader header;
  try {
    io.SetFileName(path.string());
    io.ReadImageInformation();
    const unsigned n = io.GetNumberOfDimensions();
    for (unsigned axis = 0; axis < n; ++axis) {
      header.dims.push_back(static_cast<int64_t>(io.GetDimensions(axis)));
      header.spacing.push_back(io.GetSpacing(axis));
    }
    header.grid.dims = {1, 1, 1};
    for (unsigned axis = 0; axis < std::min(n, 3u); ++axis) {
      header.grid.dims[axis] = header.dims[axis];
      header.grid.spacing[axis] = header.spacing[axis];
      header.grid.origin[axis] = io.GetOrigin(axis);
      const std::vector<double> column = io.GetDirection(axis);
      for (unsigned row = 0; row < std::min<size_t>(column.size(), 3); ++row) {
        header.grid.direction[3 * row + axis] = column[row];
      }
    }
    header.type = voxel_type_from_itk(static_cast<int>(io.GetComponentType()));
    header.components = io.GetNumberOfComponents();
    header.component_size = io.GetComponentSize();
  } catch (const itk::ExceptionObject& e) {
    throw itk_error(path, "cannot read the header", e);
  }
  return header;
}

void read_itk_voxels(itk::ImageIOBase& io, const fs::path& path, const ItkHeader& header,
                     VoxelSink& sink) {
  const size_t count = header.grid.voxel_count();
  std::vector<unsigned char> buffer(count * header.component_size);
  try {
    itk::ImageIORegion region(io.GetNumberOfDimensions());
    for (unsigned axis = 0; axis < io.GetNumberOfDimensions(); ++axis) {
      region.SetIndex(axis, 0);
      region.SetSize(axis, io.GetDimensions(axis));
    }
    io.SetIORegion(region);
    io.Read(buffer.data());
  } catch (const itk::ExceptionObject& e) {
    throw itk_error(path, "cannot read the image data; the file is truncated or corrupt", e);
  }
  sink.append(*header.type, buffer.data(), count);
}

}  // namespace segmesh::volume_io
