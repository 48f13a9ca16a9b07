// segmesh mesh INPUT -o OUTPUT [options]: the main job. Reads a label map (or a grey-value volume
// with --iso), splits it into parts, extracts each with Marching Cubes, writes the meshes and a
// report. Every check that can fail on the user's input runs before the long work starts.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "mesh_report.hpp"
#include "progress_bar.hpp"
#include "segmesh/error.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/label_names.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh::cli {

namespace fs = std::filesystem;

namespace {

struct MeshArgs {
  std::string input;
  std::string output;
  std::string method = "mc";
  std::vector<int32_t> labels;
  std::optional<double> iso;
  int connectivity = 26;
  int64_t min_voxels = 0;
  std::string normals = "central";
  std::string label_names;
  std::string format;
  std::string report;
  double presmooth = 0;
  std::string smooth = std::string(smooth_method_name(default_smoothing().method));
  SmoothOptions smooth_options = default_smoothing();
  std::string color = "material";
  double dc_svd_eps = MeshingOptions{}.dc_svd_eps;
  double dc_tolerance = 0;
  int threads = 0;
  bool quiet = false;
};

// Where the meshes go: one file, or a folder with one file per part.
struct OutputTarget {
  fs::path path;
  bool folder = false;
  MeshFormat format = MeshFormat::ply;
};

OutputTarget resolve_output(const MeshArgs& args) {
  OutputTarget out;
  out.path = args.output;
  std::optional<MeshFormat> requested;
  if (!args.format.empty()) {
    requested = parse_mesh_format(args.format);
    if (!requested) throw Error("--format must be stl, ply, obj or glb (got \"" + args.format + "\")");
  }
  const bool trailing_slash = !args.output.empty() && args.output.back() == '/';
  if (trailing_slash || fs::is_directory(out.path)) {
    out.folder = true;
    out.format = requested.value_or(MeshFormat::ply);
    fs::path folder = out.path;
    if (trailing_slash) folder = folder.parent_path();  // "dir/" -> "dir"
    if (!fs::exists(folder)) require_parent_folder(folder);
    out.path = folder;
    return out;
  }
  const auto format = mesh_format_from_path(out.path);
  if (!format) {
    throw Error(args.output + ": unknown mesh format \"" + out.path.extension().string() +
                "\"; use .stl, .ply, .obj or .glb, or end the path with / for one file per part");
  }
  if (requested && *requested != *format) {
    throw Error(args.output + ": --format " + args.format + " disagrees with the file extension");
  }
  out.format = *format;
  require_parent_folder(out.path);
  return out;
}

void refuse_to_overwrite(const fs::path& output, const fs::path& input) {
  std::error_code ec;
  if (fs::exists(output, ec) && fs::equivalent(output, input, ec)) {
    throw Error(output.string() + ": is the input; choose another output path");
  }
}

nlohmann::json options_json(const MeshArgs& a, const OutputTarget& out) {
  nlohmann::json j = {{"method", a.method},
                      {"labels", a.labels},
                      {"connectivity", a.connectivity},
                      {"min_voxels", a.min_voxels},
                      {"normals", a.normals},
                      {"format", extension(out.format)},
                      {"output", out.path.string()},
                      {"per_part_files", out.folder},
                      {"threads", a.threads},
                      {"presmooth_mm", a.presmooth},
                      {"smooth",
                       {{"method", a.smooth},
                        {"iterations", a.smooth_options.iterations},
                        {"lambda", a.smooth_options.lambda},
                        {"alpha", a.smooth_options.alpha},
                        {"beta", a.smooth_options.beta},
                        {"taubin_lambda", a.smooth_options.taubin_lambda},
                        {"taubin_mu", a.smooth_options.taubin_mu},
                        {"pass_band", a.smooth_options.pass_band},
                        {"sinc_unit_gain", a.smooth_options.sinc_unit_gain},
                        {"preserve_volume", a.smooth_options.preserve_volume}}},
                      {"color", a.color},
                      {"dc_svd_eps", a.dc_svd_eps},
                      {"dc_tolerance_mm", a.dc_tolerance}};
  j["iso"] = a.iso ? nlohmann::json(*a.iso) : nlohmann::json(nullptr);
  j["label_names"] = a.label_names.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.label_names);
  return j;
}

int run_mesh(const MeshArgs& args) {
  const auto start = std::chrono::steady_clock::now();
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
  if (args.color != "material" && args.color != "quality") {
    throw Error("--color must be material or quality (got \"" + args.color + "\")");
  }
  options.color_by_quality = args.color == "quality";
  const OutputTarget target = resolve_output(args);
  refuse_to_overwrite(target.path, args.input);
  if (!args.report.empty()) require_parent_folder(args.report);
  if (!args.label_names.empty()) options.label_names = read_label_names(args.label_names);
  const auto threads = limit_threads(args.threads);

  Timings t;
  auto step = std::chrono::steady_clock::now();
  const Image image = read_input(args.input);
  t.read = ms_since(step);

  ProgressBar progress(!args.quiet);
  PipelineStats pipeline;
  Scene unsmoothed;
  const Scene scene = build_scene(image, options, progress, &pipeline,
                                  args.report.empty() ? nullptr : &unsmoothed);
  progress.finish();
  t.components = pipeline.components_ms;
  t.extract = pipeline.extract_ms;
  t.smooth = pipeline.smooth_ms;

  step = std::chrono::steady_clock::now();
  std::vector<std::string> outputs;
  if (target.folder) {
    for (const fs::path& p : write_parts(scene, target.path, target.format)) outputs.push_back(p.string());
  } else {
    write_scene(scene, target.path, target.format);
    outputs.push_back(target.path.string());
  }
  t.write = ms_since(step);
  t.total = ms_since(start);

  const std::vector<MeshMeasures> measures = measure_parts(scene);
  if (!args.report.empty()) {
    const auto report = mesh_report(image, options_json(args, target), t, pipeline, scene,
                                    options.smooth.method == SmoothMethod::none ? nullptr : &unsmoothed,
                                    measures, outputs);
    AtomicFile file(args.report);
    file.stream() << report.dump(2) << '\n';
    file.commit();
  }
  if (!args.quiet) {
    std::printf("%s", summary_table(scene, measures).c_str());
    std::printf("%zu parts", scene.parts.size());
    if (pipeline.dropped_components > 0) {
      std::printf(" (%lld components below --min-voxels dropped)",
                  (long long)pipeline.dropped_components);
    }
    if (pipeline.presmooth_fallbacks > 0) {
      std::printf(" (%lld parts thinner than the --presmooth kernel meshed unsmoothed)",
                  (long long)pipeline.presmooth_fallbacks);
    }
    std::printf(" in %.0f ms (read %.0f, components %.0f, extract %.0f, smooth %.0f, write %.0f)\n",
                t.total, t.read, t.components, t.extract, t.smooth, t.write);
    std::printf("wrote %s%s\n", target.path.string().c_str(),
                target.folder ? (" (" + std::to_string(outputs.size()) + " files)").c_str() : "");
    if (!args.report.empty()) std::printf("report %s\n", args.report.c_str());
  }
  return 0;
}

}  // namespace

Subcommand add_mesh_command(CLI::App& app) {
  auto a = std::make_shared<MeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Mesh every part (connected component of each label) of a label map");
  cmd->add_option("input", a->input, "volume file (.nii, .nii.gz, .nrrd, .seg.nrrd, .mha, .mrc, ...) or DICOM folder")
      ->required();
  cmd->add_option("-o,--output", a->output,
                  "one file for all parts (scene.glb, .ply, .stl, .obj) or a folder ending in / "
                  "for one file per part")
      ->required();
  cmd->add_option("--method", a->method, "extraction: mc (Marching Cubes) or dc (Dual Contouring)")
      ->capture_default_str();
  cmd->add_option("--labels", a->labels, "labels to mesh, e.g. 1,2 (default: every non-zero label)")
      ->delimiter(',');
  cmd->add_option("--iso", a->iso, "mesh a grey-value volume (e.g. CT in HU) at this value");
  cmd->add_option("--connectivity", a->connectivity, "voxel connectivity of parts: 6, 18 or 26")
      ->capture_default_str();
  cmd->add_option("--min-voxels", a->min_voxels, "drop components with fewer voxels")->capture_default_str();
  cmd->add_option("--normals", a->normals, "vertex normals: central or sobel")->capture_default_str();
  cmd->add_option("--presmooth", a->presmooth,
                  "Gaussian sigma in mm applied to each part before extraction (0: off; costs volume)")
      ->capture_default_str();
  cmd->add_option("--dc-svd-eps", a->dc_svd_eps,
                  "Dual Contouring: drop QEF singular values below this fraction of the largest")
      ->capture_default_str();
  cmd->add_option("--dc-tolerance", a->dc_tolerance,
                  "Dual Contouring: simplify flat regions up to this error in mm (0: off)")
      ->capture_default_str();
  cmd->add_option("--smooth", a->smooth, "smoothing: none, laplacian, hc, taubin or sinc")
      ->capture_default_str();
  auto& so = a->smooth_options;
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
  cmd->add_option("--color", a->color, "vertex colours: material or quality (radii ratio, blue 0 to green 1)")
      ->capture_default_str();
  cmd->add_option("--label-names", a->label_names, "TSV file: label, name[, role bone|implant|other]");
  cmd->add_option("--format", a->format, "file format for a folder output: stl, ply (default), obj, glb");
  cmd->add_option("--report", a->report, "write a JSON report to this file");
  cmd->add_option("--threads", a->threads, "worker threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--quiet", a->quiet, "no progress bar and no summary");
  return {cmd, [a] { return run_mesh(*a); }};
}

}  // namespace segmesh::cli
