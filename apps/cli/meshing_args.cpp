#include "meshing_args.hpp"

#include "segmesh/error.hpp"
#include "segmesh_io/label_names.hpp"

namespace segmesh::cli {

void add_meshing_options(CLI::App* cmd, MeshingArgs& a) {
  cmd->add_option("--method", a.method, "extraction: mc (Marching Cubes) or dc (Dual Contouring)")
      ->capture_default_str();
  cmd->add_option("--labels", a.labels, "labels to mesh, e.g. 1,2 (default: every non-zero label)")
      ->delimiter(',');
  cmd->add_option("--iso", a.iso, "mesh a grey-value volume (e.g. CT in HU) at this value");
  cmd->add_option("--connectivity", a.connectivity, "voxel connectivity of parts: 6, 18 or 26")
      ->capture_default_str();
  cmd->add_option("--min-voxels", a.min_voxels, "drop components with fewer voxels")->capture_default_str();
  cmd->add_option("--normals", a.normals, "vertex normals: central or sobel")->capture_default_str();
  cmd->add_option("--presmooth", a.presmooth,
                  "Gaussian sigma in mm applied to each part before extraction (0: off; costs volume)")
      ->capture_default_str();
  cmd->add_option("--dc-svd-eps", a.dc_svd_eps,
                  "Dual Contouring: drop QEF singular values below this fraction of the largest")
      ->capture_default_str();
  cmd->add_option("--dc-tolerance", a.dc_tolerance,
                  "Dual Contouring: simplify flat regions up to this error in mm (0: off)")
      ->capture_default_str();
  cmd->add_option("--smooth", a.smooth, "smoothing: none, laplacian, hc, taubin or sinc")
      ->capture_default_str();
  auto& so = a.smooth_options;
  cmd->add_option("--iterations", so.iterations, "smoothing iterations (0: the method's default)")
      ->capture_default_str();
  cmd->add_option("--lambda", so.lambda, "Laplacian step (1: move to the neighbour average)")
      ->capture_default_str();
  cmd->add_option("--alpha", so.alpha, "HC: weight of the original positions")->capture_default_str();
  cmd->add_option("--beta", so.beta, "HC: weight of a vertex's own correction")->capture_default_str();
  cmd->add_option("--taubin-lambda", so.taubin_lambda, "Taubin: shrinking step")->capture_default_str();
  cmd->add_option("--taubin-mu", so.taubin_mu, "Taubin: inflating step (negative)")->capture_default_str();
  cmd->add_option("--pass-band", so.pass_band, "windowed sinc: pass band (3D Slicer: 0.01)")
      ->capture_default_str();
  cmd->add_flag("!--no-preserve-volume", so.preserve_volume,
                "do not restore each part's volume after smoothing (the plain filter)");
  cmd->add_flag("!--no-unit-gain", so.sinc_unit_gain,
                "windowed sinc exactly as VTK and 3D Slicer (a slight scaling, f(0) != 1)");
  cmd->add_option("--label-names", a.label_names, "TSV file: label, name[, role bone|implant|other]");
}

MeshingOptions meshing_options(const MeshingArgs& args) {
  MeshingOptions options;
  const auto method = parse_method(args.method);
  if (!method) throw Error("--method must be mc or dc (got \"" + args.method + "\")");
  options.method = *method;
  const auto normals = parse_normals(args.normals);
  if (!normals) throw Error("--normals must be central or sobel (got \"" + args.normals + "\")");
  options.normals = *normals;
  for (int32_t label : args.labels) {
    if (label == 0) throw Error("--labels: 0 is the background and has no surface");
  }
  options.labels = args.labels;
  options.iso = args.iso;
  options.connectivity = args.connectivity;
  options.min_voxels = args.min_voxels;
  options.presmooth_sigma_mm = args.presmooth;
  options.dc_svd_eps = args.dc_svd_eps;
  options.dc_tolerance_mm = args.dc_tolerance;
  const auto smooth = parse_smooth_method(args.smooth);
  if (!smooth) {
    throw Error("--smooth must be none, laplacian, hc, taubin or sinc (got \"" + args.smooth + "\")");
  }
  options.smooth = args.smooth_options;
  options.smooth.method = *smooth;
  if (!args.label_names.empty()) options.label_names = read_label_names(args.label_names);
  return options;
}

namespace {

// The iterations the smoothing runs: --iterations, else the method's default.
int effective_iterations(const MeshingArgs& a) {
  if (a.smooth_options.iterations > 0) return a.smooth_options.iterations;
  const auto method = parse_smooth_method(a.smooth);
  return method ? default_smooth_iterations(*method) : 0;
}

}  // namespace

nlohmann::json meshing_json(const MeshingArgs& a) {
  nlohmann::json j = {{"method", a.method},
                      {"labels", a.labels},
                      {"connectivity", a.connectivity},
                      {"min_voxels", a.min_voxels},
                      {"normals", a.normals},
                      {"presmooth_mm", a.presmooth},
                      {"smooth",
                       {{"method", a.smooth},
                        {"iterations", effective_iterations(a)},
                        {"lambda", a.smooth_options.lambda},
                        {"alpha", a.smooth_options.alpha},
                        {"beta", a.smooth_options.beta},
                        {"taubin_lambda", a.smooth_options.taubin_lambda},
                        {"taubin_mu", a.smooth_options.taubin_mu},
                        {"pass_band", a.smooth_options.pass_band},
                        {"sinc_unit_gain", a.smooth_options.sinc_unit_gain},
                        {"preserve_volume", a.smooth_options.preserve_volume}}},
                      {"dc_svd_eps", a.dc_svd_eps},
                      {"dc_tolerance_mm", a.dc_tolerance}};
  j["iso"] = a.iso ? nlohmann::json(*a.iso) : nlohmann::json(nullptr);
  j["label_names"] = a.label_names.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.label_names);
  return j;
}

}  // namespace segmesh::cli
