// Image: what a volume reader hands to the pipeline. Integer files become a LabelVolume (a label
// map, or integer grey values such as CT in HU when meshed with an iso value); floating-point files
// become a ScalarVolume.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "segmesh/label_info.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

struct Image {
  std::string path;        // where it was read from, for messages and reports
  std::string voxel_type;  // the file's own voxel type: "uint8", "int16", "float32", ...
  std::variant<LabelVolume, ScalarVolume> volume;
  std::vector<LabelInfo> labels;  // names/colours the file itself carries (.seg.nrrd)

  const Grid& grid() const {
    return std::visit([](const auto& v) -> const Grid& { return v.grid; }, volume);
  }
  bool is_integer() const { return std::holds_alternative<LabelVolume>(volume); }
};

}  // namespace segmesh
