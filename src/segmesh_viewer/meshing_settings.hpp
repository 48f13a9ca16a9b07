// The meshing panel's fields and their conversion to the pipeline's MeshingOptions (pipeline.hpp).
// The defaults are the pipeline's own (Marching Cubes, central-difference normals, the default
// smoothing of default_smoothing() with its method's default iteration count, every label), so
// "Create mesh" without changes gives what `segmesh mesh` gives.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "segmesh/pipeline.hpp"

namespace segmesh::viewer {

struct MeshingSettings {
  Method method = MeshingOptions{}.method;
  NormalMethod normals = MeshingOptions{}.normals;
  SmoothMethod smooth = default_smoothing().method;
  int iterations = default_smooth_iterations(default_smoothing().method);
  std::string labels;  // "1,2" or "1 2"; empty: every non-zero label
};

// The labels in `text` (integers separated by commas and/or spaces); throws segmesh::Error saying
// what is wrong ("labels: \"x\" is not a whole number").
std::vector<int32_t> parse_label_list(const std::string& text);

// The pipeline's options for these settings (everything else at the pipeline's defaults). Throws
// segmesh::Error for labels that do not parse or a negative iteration count.
MeshingOptions meshing_options(const MeshingSettings& settings);

}  // namespace segmesh::viewer
