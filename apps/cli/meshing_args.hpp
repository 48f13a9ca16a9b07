// The meshing options `segmesh mesh` and `segmesh render` share: one registration of the command
// line options and one conversion to MeshingOptions, so both commands mesh a volume the same way.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "segmesh/pipeline.hpp"

namespace segmesh::cli {

struct MeshingArgs {
  std::string method = "mc";
  std::vector<int32_t> labels;
  std::optional<double> iso;
  int connectivity = 26;
  int64_t min_voxels = 0;
  std::string normals = "central";
  std::string label_names;
  double presmooth = 0;
  std::string smooth = std::string(smooth_method_name(default_smoothing().method));
  // The default smoothing's parameters, with iterations 0: each method's own count unless
  // --iterations is given (the default sinc's 20 included).
  SmoothOptions smooth_options = [] {
    SmoothOptions o = default_smoothing();
    o.iterations = 0;
    return o;
  }();
  double dc_svd_eps = MeshingOptions{}.dc_svd_eps;
  double dc_tolerance = 0;
};

// Adds --method, --labels, --iso, --connectivity, --min-voxels, --normals, --presmooth,
// --dc-svd-eps, --dc-tolerance, --smooth and its parameters, and --label-names to `cmd`.
void add_meshing_options(CLI::App* cmd, MeshingArgs& args);

// Checks the arguments and converts them; throws segmesh::Error naming the option at fault.
// Reads the --label-names file. Leaves color_by_quality false.
MeshingOptions meshing_options(const MeshingArgs& args);

// The arguments as the JSON report records them (method, labels, ..., smooth, dc_*).
nlohmann::json meshing_json(const MeshingArgs& args);

}  // namespace segmesh::cli
