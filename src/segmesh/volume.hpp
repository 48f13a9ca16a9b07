// Volume<T>: a Grid plus its voxels, x fastest. The kinds the pipeline meets: integer volumes
// (labels, or integer grey values such as CT in HU) kept in the narrowest of uint8, int16, uint16
// and int32 that holds the file's type, so a uint8 label map costs one byte per voxel; and
// ScalarVolume (floating-point grey values, as float). LabelVolume is the widest integer kind.
#pragma once

#include <cstdint>
#include <variant>
#include <vector>

#include "segmesh/grid.hpp"

namespace segmesh {

template <class T>
struct Volume {
  Grid grid;
  std::vector<T> voxels;  // grid.voxel_count() values

  T& at(int64_t i, int64_t j, int64_t k) { return voxels[grid.index(i, j, k)]; }
  const T& at(int64_t i, int64_t j, int64_t k) const { return voxels[grid.index(i, j, k)]; }
};

using LabelVolume = Volume<int32_t>;
using ScalarVolume = Volume<float>;

// Every voxel type an Image stores (image.hpp); the integer ones first.
using AnyVolume =
    std::variant<Volume<uint8_t>, Volume<int16_t>, Volume<uint16_t>, Volume<int32_t>, Volume<float>>;

}  // namespace segmesh
