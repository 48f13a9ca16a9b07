// The pipeline: the one path from a volume to a scene of meshed parts. The command line, the
// viewer, the benchmarks and the tests all call build_scene; none of them re-implements a step.
//
//   volume ──► select labels ──► connected components ──► [volume smoothing] ──► extract (MC | DC)
//          ──► mesh smoothing ──► [decimation] ──► [quality colours] ──► Scene
//
// Options come resolved from meshing_options.hpp (build_scene resolves them again, so a caller may
// pass a request). Label maps: every selected label is split into connected components
// (components.hpp) and each component becomes a Part. With conforming surfaces (the default for
// label maps and Marching Cubes) and parts that touch, all parts are extracted at once
// (multi_label_marching_cubes.hpp), each contact meshed once, smoothed jointly
// (joint_smoothing.hpp), and each part's mesh is its closed shell cut from that one surface.
// Otherwise each part is extracted from its own 0/1 indicator at 0.5 by extract_part
// (extract_part.hpp: the one dispatch over source, method and volume smoothing), and closed on
// its own. Grey-value volumes (--iso): the
// voxels at or above iso are split the same way and each component is extracted from the grey
// values themselves. Parts are extracted in parallel, each reporting its progress inside its own
// extraction; the result does not depend on the number of threads.
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/image.hpp"
#include "segmesh/label_info.hpp"
#include "segmesh/label_stats.hpp"
#include "segmesh/meshing_options.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/scene.hpp"

namespace segmesh {

struct PipelineStats {
  double components_ms = 0;
  double extract_ms = 0;
  double smooth_ms = 0;  // the smoothing and, when asked, the quality colours
  double decimate_ms = 0;
  DecimationStats decimation;  // when decimated
  int64_t dropped_components = 0;  // smaller than min_voxels
  int64_t presmooth_fallbacks = 0;  // parts volume smoothing would have erased, meshed without it
  bool parts_touch = false;  // label maps: some parts touch (their contacts are shared only when
                             // the surfaces are conforming)
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
  bool touching = false;     // label maps: some kept parts touch (components_touch)
};
PipelineParts find_parts(const Image& image, const MeshingOptions& options,
                         Progress& progress = null_progress());
// 2. One Part per kept component, extracted in parallel (not smoothed).
Scene extract_parts(const Image& image, const PipelineParts& parts, const MeshingOptions& options,
                    Progress& progress = null_progress(), int64_t* presmooth_fallbacks = nullptr);
// 3. smooth_scene (below); 4. decimate_scene (decimation.hpp) when asked; then
//    color_scene_by_quality when asked.

// Builds the scene. Throws segmesh::Error (naming image.path) for requests the volume cannot
// satisfy: a float volume without iso, a label that is not in the volume, no foreground at all,
// nothing left after --min-voxels, invalid options. Throws Cancelled when progress is cancelled.
// With `extracted`, also returns every part's positions as extracted, before smoothing (for
// reports that say how far smoothing moved the surface: scene_measures.hpp), and when the scene
// is decimated every part's mesh before decimation (for the decimation's error).
Scene build_scene(const Image& image, const MeshingOptions& options,
                  Progress& progress = null_progress(), PipelineStats* timings = nullptr,
                  ExtractedPositions* extracted = nullptr);
// As build_scene, freeing the image's voxels once extraction is done (the grid, path and names
// stay), so the steps after it do not carry the volume: for a front end that is done with the
// volume and wants its peak memory down.
Scene build_scene_releasing(Image& image, const MeshingOptions& options,
                            Progress& progress = null_progress(), PipelineStats* timings = nullptr,
                            ExtractedPositions* extracted = nullptr);

// The smoothing step on its own: every part smoothed in parallel (normals recomputed); then
// quality colours when asked. build_scene ends with it; the study runs it with many settings.
// On a shared surface, smoothed once and its shells cut again; with `origin`, each shell vertex's
// surface vertex (part_shells).
void smooth_scene(Scene& scene, const SmoothOptions& options, Progress& progress = null_progress(),
                  ShellOrigins* origin = nullptr);

// Sets every part's vertex colours from its radii ratios (blue 0 to green 1).
void color_scene_by_quality(Scene& scene);

// The name of a part: "<label name>_<k>", "label<L>_<k>" for unnamed labels, "iso<V>_<k>" for
// grey-value components.
std::string part_name(std::string_view base, int component);

}  // namespace segmesh
