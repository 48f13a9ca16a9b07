// The numbers of a scene's parts that every front end reports, measured once here: the CLI's
// summary table and JSON report (apps/cli/mesh_report.cpp), the viewer's part table and quality
// view (segmesh_viewer/part_stats.hpp), and the batch runs and the Python package after them.
// Per part: the mesh measures (mesh_measures.hpp: counts, area, enclosed volume, closedness),
// the radii-ratio quality (quality.hpp), and, given the positions before smoothing, the volume
// before smoothing and how far smoothing moved the surface (moved_mesh_deviation.hpp), and when
// the scene was decimated how far decimation moved it (mesh_deviation); and for
// conforming surfaces, per pair of touching parts, the contact's area and whether its two sides
// are one surface in the shells as written.
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
  // Given the mesh before decimation (ExtractedPositions::undecimated): its triangle count and
  // the deviation of the decimated mesh from it (mesh_deviation: samples at the vertices and
  // triangle centroids of both meshes, each measured exactly against the other mesh).
  std::optional<int64_t> triangles_before_decimation;
  std::optional<Deviation> decimation_deviation;
};

// Two touching parts of a scene meshed with conforming surfaces (Scene::surface): their common
// surface's area and the largest distance from one of its vertices to either part's shell as
// written (each shell is searched exactly: 0 up to float rounding when the two sides are one
// surface, as they should be).
struct ContactMeasures {
  size_t a = 0, b = 0;  // part indices, a < b
  double area_mm2 = 0;
  double max_gap_mm = 0;
};

struct SceneMeasures {
  std::vector<PartMeasures> parts;       // in scene order
  std::vector<ContactMeasures> contacts;  // ordered by (a, b); empty without Scene::surface
};

struct MeasureRequest {
  bool quality = true;
  bool contacts = true;  // with conforming surfaces: every contact's area and gap
  // The positions before smoothing (ExtractedPositions, one entry per part, each as long as the
  // part's positions, or as its undecimated mesh's when the scene was decimated), or nullptr: no
  // volume change and no deviations.
  const ExtractedPositions* extracted = nullptr;
};

// One part's measures; `extracted` is its positions before smoothing, or nullptr; `undecimated`
// its mesh before decimation (whose triangles `extracted` then belongs to), or nullptr.
PartMeasures measure_part(const TriMesh& mesh, bool quality,
                          const std::vector<Vec3f>* extracted = nullptr,
                          const TriMesh* undecimated = nullptr);

// Every part's measures, and with conforming surfaces every contact's. Reports progress (the step
// "measuring", parts weighted by their triangles) and throws Cancelled when progress is cancelled.
// Throws std::invalid_argument when `extracted` does not match the scene's parts.
SceneMeasures measure_scene(const Scene& scene, const MeasureRequest& request,
                            Progress& progress = null_progress());

}  // namespace segmesh
