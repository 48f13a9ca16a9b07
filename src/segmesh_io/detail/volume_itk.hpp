// Glue between the volume readers and ITK's ImageIO classes. Internal to segmesh_io.
//
// ITK types appear here only as forward declarations: no header of segmesh_io includes ITK.
// Every function converts itk::ExceptionObject into segmesh::Error, so no ITK exception leaves
// the library.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/grid.hpp"
#include "segmesh_io/detail/voxel_sink.hpp"

namespace itk {
class ImageIOBase;
}

namespace segmesh::volume_io {

// What ITK's ReadImageInformation() reports, in ITK's LPS convention.
struct ItkHeader {
  std::vector<int64_t> dims;      // every axis the file has
  std::vector<double> spacing;    // every axis
  Grid grid;                      // the first three axes (padded when the image has fewer)
  std::optional<VoxelType> type;  // empty: a component type segmesh does not read
  unsigned components = 1;        // values per voxel
  size_t component_size = 0;      // bytes
};

// Sets the file name and runs io.ReadImageInformation().
ItkHeader read_itk_header(itk::ImageIOBase& io, const std::filesystem::path& path);

// Reads the whole image (header already read, one component per voxel) into `sink`.
void read_itk_voxels(itk::ImageIOBase& io, const std::filesystem::path& path,
                     const ItkHeader& header, VoxelSink& sink);

// The VoxelType of an itk::IOComponentEnum value (passed as its integer value so that callers'
// headers need no ITK), or nullopt.
std::optional<VoxelType> voxel_type_from_itk(int component);

// Error("<path>: <context> (<ITK's reason, one line>)").
Error itk_error(const std::filesystem::path& path, std::string_view context,
                const std::exception& e);

}  // namespace segmesh::volume_io
