// The pipeline: the one path from a volume to a scene of meshed parts. The command line, the
// viewer, the benchmarks and the tests all call build_scene; none of them re-implements a step.
//
//   volume ──► select labels ──► connected components ──► [pre-smooth] ──► extract (MC | DC)
//          ──► smooth ──► [quality colours] ──► Scene
//
// Label maps: every selected label is split into connected components (components.hpp); each
// component becomes a Part, extracted from its own 0/1 indicator at 0.5 (Marching Cubes straight
// from the component's runs, run_scan.hpp; otherwise from a mask, component_field.hpp), so parts
// never share vertices and each is closed on its own. Extraction is Marching Cubes
// (marching_cubes.hpp) or Dual Contouring (dual_contouring.hpp); with presmooth_sigma_mm > 0 the
// part's field is first smoothed by a Gaussian (gaussian_filter.hpp) so binary labels get sub-voxel
// shape, at a cost in volume. Grey-value volumes (--iso): the
// voxels at or above iso are split the same way and each component is extracted from the grey
// values themselves. Parts are extracted in parallel; the result does not depend on the number of
// threads.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/gradient.hpp"
#include "segmesh/image.hpp"
#include "segmesh/label_info.hpp"
#include "segmesh/label_stats.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {

enum class Method { marching_cubes, dual_contouring };

std::string_view method_name(Method method);
std::optional<Method> parse_method(std::string_view name);  // "mc", "dc"
std::string_view normals_name(NormalMethod normals);
std::optional<NormalMethod> parse_normals(std::string_view name);  // "central", "sobel"

// The smoothing `segmesh mesh` applies unless told otherwise (chosen by measurement:
// docs/STUDY.md).
SmoothOptions default_smoothing();

struct MeshingOptions {
  Method method = Method::marching_cubes;
  std::vector<int32_t> labels;   // labels to mesh; empty: every non-zero label
  std::optional<double> iso;     // mesh a grey-value volume at this value instead of labels
  int connectivity = 26;         // voxel connectivity of parts: 6, 18 or 26
  int64_t min_voxels = 0;        // drop components with fewer voxels (0 keeps everything)
  NormalMethod normals = NormalMethod::central;
  std::vector<LabelInfo> label_names;  // --label-names: override the names the file carries
  double presmooth_sigma_mm = 0;  // > 0: Gaussian smoothing of each part's field before extraction
  double dc_svd_eps = 0.5;        // Dual Contouring: relative singular value cut-off of the QEF
  double dc_tolerance_mm = 0;     // Dual Contouring: > 0 simplifies flat regions adaptively
  SmoothOptions smooth = default_smoothing();  // after extraction, per part
  bool color_by_quality = false;  // per-vertex colours from the worst incident radii ratio
};

struct PipelineStats {
  double components_ms = 0;
  double extract_ms = 0;
  double smooth_ms = 0;
  int64_t dropped_components = 0;  // smaller than min_voxels
  int64_t presmooth_fallbacks = 0;  // parts pre-smoothing would have erased, meshed unsmoothed
};

// A label map with more distinct values than this is taken for a grey-value image unless the
// labels to mesh are named explicitly.
inline constexpr size_t kMaxLabelsWithoutSelection = 1000;

// The pipeline's steps, for front ends that time or repeat one of them (the benchmarks);
// build_scene runs them in this order.
// 1. The connected components of the selected labels (or of the voxels at or above --iso), in
//    components.hpp's order, and which of them are meshed (--min-voxels).
struct PipelineParts {
  Components components;
  std::vector<size_t> kept;  // indices into components.components, in order
  ValueRange range;          // grey-value volumes: the value range (the background outside)
};
PipelineParts find_parts(const Image& image, const MeshingOptions& options,
                         Progress& progress = null_progress());
// 2. One Part per kept component, extracted in parallel (not smoothed).
Scene extract_parts(const Image& image, const PipelineParts& parts, const MeshingOptions& options,
                    Progress& progress = null_progress(), int64_t* presmooth_fallbacks = nullptr);
// 3. smooth_scene (below), then color_scene_by_quality when asked.

// Builds the scene. Throws segmesh::Error (naming image.path) for requests the volume cannot
// satisfy: a float volume without iso, a label that is not in the volume, no foreground at all,
// nothing left after --min-voxels, invalid options. Throws Cancelled when progress is cancelled.
// With `unsmoothed`, also returns the scene as extracted, before smoothing (for reports that say
// how far smoothing moved the surface).
Scene build_scene(const Image& image, const MeshingOptions& options,
                  Progress& progress = null_progress(), PipelineStats* timings = nullptr,
                  Scene* unsmoothed = nullptr);
// As build_scene, freeing the image's voxels once extraction is done (the grid, path and names
// stay), so the steps after it do not carry the volume: for a front end that is done with the
// volume and wants its peak memory down.
Scene build_scene_releasing(Image& image, const MeshingOptions& options,
                            Progress& progress = null_progress(), PipelineStats* timings = nullptr,
                            Scene* unsmoothed = nullptr);

// The smoothing step on its own: every part smoothed in parallel (normals recomputed); then
// quality colours when asked. build_scene ends with it; the study runs it with many settings.
void smooth_scene(Scene& scene, const SmoothOptions& options, Progress& progress = null_progress());

// Sets every part's vertex colours from its radii ratios (blue 0 to green 1).
void color_scene_by_quality(Scene& scene);

// The name of a part: "<label name>_<k>", "label<L>_<k>" for unnamed labels, "iso<V>_<k>" for
// grey-value components.
std::string part_name(std::string_view base, int component);

}  // namespace segmesh
