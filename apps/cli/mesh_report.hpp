// The JSON report of `segmesh mesh --report` and the summary table it prints, both from the
// parts' measures (segmesh/scene_measures.hpp): per part the topology checks, radii ratio, the
// volume change smoothing made and how far it moved the surface (null deviation, zero change,
// when not smoothed), and with conforming surfaces every contact's area and largest gap.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/scene_measures.hpp"

namespace segmesh::cli {

// The wall time of every step of the command, in milliseconds. They partition the run: measure is
// the time the measuring added after the write it runs beside, report the time to assemble the
// report, and other what no step accounts for (options, output checks, the summary).
struct Timings {
  double read = 0, components = 0, extract = 0, smooth = 0, decimate = 0, write = 0, measure = 0,
         report = 0, total = 0;
  double steps() const {
    return read + components + extract + smooth + decimate + write + measure + report;
  }
};

nlohmann::json mesh_report(const Image& image, const nlohmann::json& options, const Timings& timings,
                           const PipelineStats& stats, const Scene& scene,
                           const SceneMeasures& measures,
                           const std::vector<std::string>& outputs);

// A table of the parts for stdout.
std::string summary_table(const Scene& scene, const std::vector<PartMeasures>& measures);

}  // namespace segmesh::cli
