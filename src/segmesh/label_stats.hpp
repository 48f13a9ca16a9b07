// Label and value statistics of a volume: which labels occur and how often, the value range.
// One parallel pass over the voxels; results are sorted and independent of the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "segmesh/volume.hpp"

namespace segmesh {

struct LabelCount {
  int32_t label = 0;
  int64_t voxels = 0;
};

// Every value that occurs (0 included), ascending; T an integer voxel type of AnyVolume.
template <class T>
std::vector<LabelCount> count_labels(const Volume<T>& volume);

struct ValueRange {
  double min = 0, max = 0;  // over finite values
  int64_t non_finite = 0;   // NaN and infinite voxels (float volumes only)
};

template <class T>
ValueRange value_range(const Volume<T>& volume);

extern template std::vector<LabelCount> count_labels(const Volume<uint8_t>&);
extern template std::vector<LabelCount> count_labels(const Volume<int16_t>&);
extern template std::vector<LabelCount> count_labels(const Volume<uint16_t>&);
extern template std::vector<LabelCount> count_labels(const Volume<int32_t>&);
extern template ValueRange value_range(const Volume<uint8_t>&);
extern template ValueRange value_range(const Volume<int16_t>&);
extern template ValueRange value_range(const Volume<uint16_t>&);
extern template ValueRange value_range(const Volume<int32_t>&);
extern template ValueRange value_range(const Volume<float>&);

}  // namespace segmesh
