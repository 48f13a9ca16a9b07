// Image: what a volume reader hands to the pipeline. Integer files become an integer volume in the
// narrowest of uint8, int16, uint16, int32 that holds the file's type (a label map, or integer grey
// values such as CT in HU when meshed with an iso value); floating-point files a ScalarVolume.
#pragma once

#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "segmesh/label_info.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

struct Image {
  std::string path;        // where it was read from, for messages and reports
  std::string voxel_type;  // the file's own voxel type: "uint8", "int16", "float32", ...
  AnyVolume volume;
  std::vector<LabelInfo> labels;  // names/colours the file itself carries (.seg.nrrd)

  const Grid& grid() const {
    return std::visit([](const auto& v) -> const Grid& { return v.grid; }, volume);
  }
  bool is_integer() const { return !std::holds_alternative<ScalarVolume>(volume); }

  // The voxels of an integer image widened to int32 (a copy; for tools and tests). Throws
  // std::bad_variant_access for a ScalarVolume.
  LabelVolume labels_int32() const {
    return std::visit(
        [](const auto& v) -> LabelVolume {
          using T = typename std::decay_t<decltype(v.voxels)>::value_type;
          if constexpr (std::is_same_v<T, float>) {
            throw std::bad_variant_access();
          } else {
            return {v.grid, std::vector<int32_t>(v.voxels.begin(), v.voxels.end())};
          }
        },
        volume);
  }
};

}  // namespace segmesh
