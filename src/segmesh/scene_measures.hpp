// The numbers of a scene's parts that every front end reports, measured once here: the CLI's
// summary table and JSON report (apps/cli/mesh_report.cpp), the viewer's part table and quality
// view (segmesh_viewer/part_stats.hpp), and the batch runs and the Python package after them.
// Per part: the mesh measures (mesh_measures.hpp: counts, area, enclosed volume, closedness),
// the radii-ratio quality (quality.hpp), and, given the positions before smoothing, the volume
// before smoothing and how far smoothing moved the surface (moved_mesh_deviation.hpp).
//
// Parts run in parallel; each part's measures run one after the other, each parallel inside, so
// the largest part's working memory (edge rows, trees) is alive once at a time.
#pragma once

#include <optional>
#include <vector>

#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene.hpp"

namespace segmesh {

struct PartMeasures {
  MeshMeasures mesh;
  std::optional<QualityStats> quality;       // when asked for
  std::optional<double> volume_before_mm3;   // given the extracted positions
  std::optional<Deviation> smoothing_deviation;  // given the extracted positions
};

struct MeasureRequest {
  bool quality = true;
  // The positions before smoothing (ExtractedPositions, one entry per part, each as long as the
  // part's positions), or nullptr: no volume change and no deviation.
  const ExtractedPositions* extracted = nullptr;
};

// One part's measures; `extracted` is its positions before smoothing, or nullptr.
PartMeasures measure_part(const TriMesh& mesh, bool quality,
                          const std::vector<Vec3f>* extracted = nullptr);

// Every part's measures, in scene order. Reports progress (the step "measuring", parts weighted by
// their triangles) and throws Cancelled when progress is cancelled. Throws std::invalid_argument
// when `extracted` does not match the scene's parts.
std::vector<PartMeasures> measure_scene(const Scene& scene, const MeasureRequest& request,
                                        Progress& progress = null_progress());

}  // namespace segmesh
