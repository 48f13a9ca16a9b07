// VoxelType: the element type a volume file stores its voxels in. Internal to segmesh_io.
//
// Every reader maps its format's own type code (NIfTI datatype, MetaImage ElementType, MRC mode,
// the ITK component type for NRRD and DICOM) to this one enum, so the decoding (voxel_sink.hpp),
// the sizes and the names Image::voxel_type reports ("uint8", ..., "float64") are written once.
// with_stored_type() calls a function with the C++ type of a file element, float16 as its raw
// bits (Half). Cost: a switch.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace segmesh::volume_io {

enum class VoxelType {
  uint8,
  int8,
  uint16,
  int16,
  uint32,
  int32,
  uint64,
  int64,
  float16,
  float32,
  float64
};

std::string_view voxel_type_name(VoxelType type);  // "uint8", ..., "float64"
size_t voxel_type_size(VoxelType type);
bool is_integer(VoxelType type);

// An IEEE half-precision value as the file holds it (MRC mode 12); voxel_sink.cpp converts it.
struct Half {
  uint16_t bits;
};

// Calls f(T{}) with the C++ type stored for `type`.
template <class F>
void with_stored_type(VoxelType type, F&& f) {
  switch (type) {
    case VoxelType::uint8:
      return f(uint8_t{});
    case VoxelType::int8:
      return f(int8_t{});
    case VoxelType::uint16:
      return f(uint16_t{});
    case VoxelType::int16:
      return f(int16_t{});
    case VoxelType::uint32:
      return f(uint32_t{});
    case VoxelType::int32:
      return f(int32_t{});
    case VoxelType::uint64:
      return f(uint64_t{});
    case VoxelType::int64:
      return f(int64_t{});
    case VoxelType::float16:
      return f(Half{});
    case VoxelType::float32:
      return f(float{});
    case VoxelType::float64:
      return f(double{});
  }
}

}  // namespace segmesh::volume_io
