#include "segmesh_io/detail/voxel_type.hpp"

namespace segmesh::volume_io {

std::string_view voxel_type_name(VoxelType type) {
  switch (type) {
    case VoxelType::uint8:
      return "uint8";
    case VoxelType::int8:
      return "int8";
    case VoxelType::uint16:
      return "uint16";
    case VoxelType::int16:
      return "int16";
    case VoxelType::uint32:
      return "uint32";
    case VoxelType::int32:
      return "int32";
    case VoxelType::uint64:
      return "uint64";
    case VoxelType::int64:
      return "int64";
    case VoxelType::float16:
      return "float16";
    case VoxelType::float32:
      return "float32";
    case VoxelType::float64:
      return "float64";
  }
  return "unknown";
}

size_t voxel_type_size(VoxelType type) {
  size_t size = 0;
  with_stored_type(type, [&](auto tag) { size = sizeof(tag); });
  return size;
}

bool is_integer(VoxelType type) {
  return type != VoxelType::float16 && type != VoxelType::float32 && type != VoxelType::float64;
}

}  // namespace segmesh::volume_io
