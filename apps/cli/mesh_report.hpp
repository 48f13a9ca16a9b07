// The JSON report of `segmesh mesh --report` and the summary table it prints. Per part, besides
// the topology checks: radii ratio, the volume change smoothing made and how far it moved the
// surface (symmetric deviation against `unsmoothed`, the parts as extracted; null when not smoothed).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/scene.hpp"

namespace segmesh::cli {

struct Timings {
  double read = 0, components = 0, extract = 0, smooth = 0, write = 0, total = 0;
};

// Measures every part (in parallel), in scene order.
std::vector<MeshMeasures> measure_parts(const Scene& scene);

nlohmann::json mesh_report(const Image& image, const nlohmann::json& options, const Timings& timings,
                           const PipelineStats& stats, const Scene& scene,
                           const Scene* unsmoothed, const std::vector<MeshMeasures>& measures,
                           const std::vector<std::string>& outputs);

// A table of the parts for stdout.
std::string summary_table(const Scene& scene, const std::vector<MeshMeasures>& measures);

}  // namespace segmesh::cli
