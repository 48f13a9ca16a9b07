// The JSON report of a meshing run (`segmesh mesh --report`, every case of `segmesh batch`), from
// the parts' measures (segmesh/scene_measures.hpp): the input grid, the resolved options, the
// step times, per part the topology checks, radii ratio, the volume change smoothing made and how
// far it moved the surface (null deviation, zero change, when not smoothed), decimation's error,
// and with conforming surfaces every contact's area and largest gap. It formats the measures and
// measures nothing itself. In the library so that the command line, the batch case runner and
// the Python package write the same report.
#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/meshing_options.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh {

// The wall time of every step of a run, in milliseconds. They partition the run: measure is the
// time the measuring added after the write it runs beside, report the time to assemble the
// report, and other what no step accounts for (options, output checks, the summary).
struct MeshTimings {
  double read = 0, components = 0, extract = 0, smooth = 0, decimate = 0, write = 0, measure = 0,
         report = 0, total = 0;
  double steps() const {
    return read + components + extract + smooth + decimate + write + measure + report;
  }
};

// Milliseconds since `start`.
inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// What the report says of the request beyond the meshing options: where the meshes went and how.
struct ReportedRequest {
  MeshingOptions options;               // resolved
  std::string label_names;              // the --label-names file ("" for none)
  MeshTarget target;                    // as reported (the final place, not a temporary one)
  MeshWriteOptions write;
  std::string atlas;                    // "" for none
  int threads = 0;
  std::string color = "material";
  std::optional<std::string> surfaces_note;  // said: parts touch and the request got independent
};

// Writes the report of a finished run to `path` atomically (AtomicFile). `timings` gets its
// report and total times: the time to assemble the report, and the time since `start`.
void write_mesh_report(const std::filesystem::path& path, const Image& image,
                       const ReportedRequest& request, MeshTimings& timings,
                       std::chrono::steady_clock::time_point start, const PipelineStats& stats,
                       const Scene& scene, const SceneMeasures& measures,
                       const std::vector<std::string>& outputs);

}  // namespace segmesh
