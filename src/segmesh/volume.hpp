// Volume<T>: a Grid plus its voxels, x fastest. The two kinds the pipeline meets:
// LabelVolume (integer labels of any integer file type, widened to int32) and ScalarVolume
// (grey values such as CT Hounsfield units, as float).
#pragma once

#include <cstdint>
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

}  // namespace segmesh
