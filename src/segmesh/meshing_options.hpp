// Meshing options: every choice a meshing run makes, its default, its name and its check, in one
// place. The command line, the viewer, `segmesh study`, the JSON report and the benchmarks all go
// through it, so a default is decided once and every front end states it the same way.
//
// MeshingOptions is what a caller asks for. Some fields say "the method's own default" (smoothing
// iterations 0); resolve_meshing_options turns a request into what runs: every such default
// replaced by its value and every value checked, with a message naming the command-line option.
// build_scene resolves its options itself; a front end calls resolve_meshing_options before the
// long work starts (to refuse a bad request before reading a volume) and to report what ran.
//
// meshing_option_specs() lists the options by their command-line names (`--dc-svd-eps`) with
// their help, their default as text and a setter that parses text with the same checks, so a
// front end that takes options by name (the command line; keyword arguments) registers them from
// the list instead of repeating them.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "segmesh/connectivity.hpp"
#include "segmesh/decimation.hpp"
#include "segmesh/dual_contouring.hpp"
#include "segmesh/gradient.hpp"
#include "segmesh/label_info.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {

enum class Method { marching_cubes, dual_contouring };

std::string_view method_name(Method method);  // "mc", "dc"
std::optional<Method> parse_method(std::string_view name);
std::string_view normals_name(NormalMethod normals);  // "central", "sobel"

// How the parts of a label map are meshed: each on its own (independent: touching parts get two
// surfaces that smoothing moves apart), or all at once as one surface whose contacts are meshed
// once and smoothed once for both sides (conforming: multi_label_marching_cubes.hpp or
// multi_label_dual_contouring.hpp, joint_smoothing.hpp; each part is still written as its own
// closed shell). automatic, the default, resolves to conforming for label maps (either method)
// without --presmooth or --dc-tolerance, and to independent otherwise (grey values, presmoothing,
// Dual Contouring's simplification: surfaces_note says why where parts could touch); asking for
// conforming with those is an error.
enum class Surfaces { automatic, independent, conforming };
std::string_view surfaces_name(Surfaces surfaces);  // "automatic", "independent", "conforming"
std::optional<Surfaces> parse_surfaces(std::string_view name);
std::optional<NormalMethod> parse_normals(std::string_view name);

// The smoothing `segmesh mesh` applies unless told otherwise: windowed sinc with unit gain, pass
// band 0.01, the method's default iterations (20), the volume restored. On voxelised spheres of
// 8-40 mm it comes closer to the true sphere than 3D Slicer's default (the same filter without
// unit gain) and keeps the volume; on the phantom and the real data it removes the staircase
// (docs/STUDY.md has the measurements).
SmoothOptions default_smoothing();

struct MeshingOptions {
  Method method = Method::marching_cubes;
  Surfaces surfaces = Surfaces::automatic;  // conforming: label maps only
  std::vector<int32_t> labels;  // labels to mesh; empty: every non-zero label
  std::optional<double> iso;    // mesh a grey-value volume at this value instead of labels
  int connectivity = kDefaultConnectivity;  // voxel connectivity of parts: 6, 18 or 26
  int64_t min_voxels = 0;       // drop components with fewer voxels (0 keeps everything)
  NormalMethod normals = NormalMethod::central;
  std::vector<LabelInfo> label_names;  // --label-names: override the names the file carries
  // Volume smoothing before extraction (`--presmooth`): > 0 is the sigma in mm of a Gaussian
  // applied to each part's field, so binary labels get sub-voxel shape at a cost in volume. Not
  // the mesh smoothing below, which moves the extracted vertices.
  double volume_sigma_mm = 0;
  double dc_svd_eps = kDefaultDcSvdEps;     // Dual Contouring: relative singular value cut-off of the QEF
  double dc_tolerance_mm = 0;  // Dual Contouring: > 0 simplifies flat regions adaptively
  SmoothOptions smooth = default_smoothing();  // mesh smoothing after extraction, per part
  DecimateOptions decimate;  // after smoothing (decimation.hpp); off by default
  bool color_by_quality = false;  // per-vertex colours from the worst incident radii ratio
};

// The options a run uses: smoothing iterations 0 replaced by the method's default
// (default_smooth_iterations), everything else as given. Throws segmesh::Error naming the
// command-line option for a value out of range ("--connectivity must be 6, 18 or 26 (got 7)").
// Idempotent.
MeshingOptions resolve_meshing_options(MeshingOptions requested);

// Why a request that leaves --surfaces automatic gets independent surfaces on a label map
// (--presmooth, --dc-tolerance), for front ends to say once when parts touch
// (PipelineStats::parts_touch); nothing
// when it gets conforming surfaces, asks for a kind itself, or meshes grey values.
std::optional<std::string> surfaces_note(const MeshingOptions& requested);

// One option by its command-line name.
struct MeshingOptionSpec {
  std::string_view name;       // "dc-svd-eps": `--dc-svd-eps` on the command line
  std::string_view type_name;  // "TEXT", "INT", "FLOAT", "INT LIST" or "FLAG"
  std::string_view help;
  // For a FLAG: the command line's `--no-<name>` turns it off (every flag is on by default).
  // Otherwise the value as text ("" for an unset optional value).
  std::string (*get)(const MeshingOptions&);
  // Parses `text` into the options (a FLAG takes "true" or "false"); throws segmesh::Error naming
  // the option for text that does not parse. Range checks are resolve_meshing_options's.
  void (*set)(MeshingOptions&, std::string_view text);
  bool is_flag() const { return type_name == "FLAG"; }
};

// Every option of MeshingOptions but label_names (a file, read by the front end) and
// color_by_quality (the output's colours, the front end's own option), in the order `--help`
// lists them.
std::span<const MeshingOptionSpec> meshing_option_specs();

// The spec named `name` (with or without the leading "--"), or nullptr.
const MeshingOptionSpec* find_meshing_option(std::string_view name);

}  // namespace segmesh
