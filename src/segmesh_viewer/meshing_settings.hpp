// The meshing panel's fields and their conversion to MeshingOptions (meshing_options.hpp). The
// defaults are the options layer's (Marching Cubes, central-difference normals, the default
// smoothing with its method's iteration count, every label), so "Create mesh" without changes
// gives what `segmesh mesh` gives.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "segmesh/meshing_options.hpp"

namespace segmesh::viewer {

struct MeshingSettings {
  Method method = MeshingOptions{}.method;
  NormalMethod normals = MeshingOptions{}.normals;
  SmoothMethod smooth = MeshingOptions{}.smooth.method;
  int iterations = resolve_meshing_options({}).smooth.iterations;
  std::string labels;  // "1,2" or "1 2"; empty: every non-zero label
};

// The labels in `text` (integers separated by commas and/or spaces); throws segmesh::Error saying
// what is wrong ("labels: \"x\" is not a whole number").
std::vector<int32_t> parse_label_list(const std::string& text);

// The resolved options for these settings (everything else at the defaults). Throws
// segmesh::Error for labels that do not parse or options out of range (a negative iteration
// count).
MeshingOptions meshing_options(const MeshingSettings& settings);

}  // namespace segmesh::viewer
