// segmesh mesh INPUT -o OUTPUT [options]: the main job. Reads a label map (or a grey-value volume
// with --iso), splits it into parts, extracts each (Marching Cubes or Dual Contouring), writes the
// meshes, the conforming surface as an atlas (--atlas) and a report. Every check that can fail on
// the user's input runs before the long work starts.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <system_error>

#include "cli_common.hpp"
#include "commands.hpp"
#include "meshing_args.hpp"
#include "progress_bar.hpp"
#include "segmesh/error.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/atlas_writer.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/mesh_job.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh::cli {

namespace fs = std::filesystem;

namespace {

struct MeshArgs {
  std::string input;
  std::string output;
  MeshingArgs meshing;
  std::string format;
  std::string report;
  std::string atlas;
  std::string color = "material";
  int threads = 0;
  bool quiet = false;
  bool quantize = false;
  ReadArgs read;
};

// Throws when the outputs of `option` and `other_option` are the same file.
void refuse_same_file(const std::string& path, const char* option, const fs::path& other,
                      const char* other_option) {
  if (same_path(path, other)) {
    throw Error(path + ": " + option + " and " + other_option +
                " name the same file; choose another name");
  }
}

// --atlas: the conforming surface, so conforming surfaces (the default for label maps); a .ply or .glb file in an existing folder (or the -o folder, made before the
// atlas is written) that is neither the input nor another output. `note` is why --surfaces
// automatic chose independent surfaces (surfaces_note).
void check_atlas(const MeshArgs& args, const MeshingOptions& options,
                 const std::optional<std::string>& note, const MeshTarget& target) {
  if (options.surfaces != Surfaces::conforming) {
    const std::string why = note ? *note
                            : options.iso ? "--iso meshes grey values, each part on its own"
                                          : "this run asks for --surfaces independent";
    throw Error("--atlas needs --surfaces conforming, the one surface all parts share; " + why);
  }
  atlas_format(args.atlas);
  const fs::path folder = fs::path(args.atlas).parent_path();
  if (!target.folder || !same_path(folder.empty() ? "." : folder, target.path)) {
    require_parent_folder(args.atlas);
  }
  refuse_to_overwrite(args.atlas, args.input);
  if (!target.folder) refuse_same_file(args.atlas, "--atlas", target.path, "-o");
  if (!args.report.empty()) refuse_same_file(args.atlas, "--atlas", args.report, "--report");
}

// A table of the parts for stdout.
std::string summary_table(const Scene& scene, const std::vector<PartMeasures>& measures) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-28s %-8s %10s %11s %14s %14s %7s %6s\n", "part", "role",
                "voxels", "triangles", "voxel_mm3", "mesh_mm3", "closed", "shells");
  out += line;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const Part& part = scene.parts[p];
    const MeshMeasures& m = measures[p].mesh;
    std::snprintf(line, sizeof line, "%-28s %-8s %10lld %11lld %14.1f %14.1f %7s %6lld\n",
                  part.name.c_str(), std::string(role_name(part.role)).c_str(),
                  (long long)part.voxels, (long long)m.triangles, part.voxel_volume_mm3,
                  m.volume_mm3, m.closed() ? "yes" : "NO", (long long)m.shells);
    out += line;
  }
  return out;
}

int run_mesh(const MeshArgs& args) {
  const auto start = std::chrono::steady_clock::now();
  const MeshingOptions request = meshing_request(args.meshing);
  const std::optional<std::string> note = surfaces_note(request);
  MeshingOptions options = resolve_meshing_options(request);
  if (args.color != "material" && args.color != "quality") {
    throw Error("--color must be material or quality (got \"" + args.color + "\")");
  }
  options.color_by_quality = args.color == "quality";
  const MeshWriteOptions write_options{.quantize = args.quantize};
  const MeshTarget target = resolve_mesh_target(args.output, args.format, write_options);
  refuse_to_overwrite(target.path, args.input);
  if (!args.report.empty()) {
    require_parent_folder(args.report);
    refuse_to_overwrite(args.report, args.input);
    if (!target.folder) refuse_same_file(args.report, "--report", target.path, "-o");
  }
  if (!args.atlas.empty()) check_atlas(args, options, note, target);
  const auto threads = limit_threads(args.threads);

  MeshTimings t;
  ProgressBar progress(!args.quiet);
  progress.step("reading");
  const auto step = std::chrono::steady_clock::now();
  Image image = read_input(args.input, args.read);
  t.read = ms_since(step);

  const MeshJob job{.request = {.options = options,
                                .label_names = args.meshing.label_names,
                                .target = target,
                                .write = write_options,
                                .atlas = args.atlas,
                                .threads = args.threads,
                                .color = args.color,
                                .surfaces_note = note},
                    .report = args.report,
                    .measure = !args.quiet,
                    .write_to = target};
  const MeshJobResult result = run_mesh_job(image, job, progress, t, start);
  const Scene& scene = result.scene;
  const PipelineStats& pipeline = result.pipeline;
  const std::vector<std::string>& outputs = result.outputs;
  const bool report = !args.report.empty();
  progress.finish();
  // Said once, after the progress bar, when parts touch.
  if (result.say_surfaces_note && !args.quiet) std::fprintf(stderr, "note: %s\n", note->c_str());
  t.total = ms_since(start);
  if (!args.quiet) {
    std::printf("%s", summary_table(scene, result.measures.parts).c_str());
    std::printf("%zu parts", scene.parts.size());
    if (pipeline.dropped_components > 0) {
      std::printf(" (%lld components below --min-voxels dropped)",
                  (long long)pipeline.dropped_components);
    }
    if (pipeline.presmooth_fallbacks > 0) {
      std::printf(" (%lld parts thinner than the --presmooth kernel meshed unsmoothed)",
                  (long long)pipeline.presmooth_fallbacks);
    }
    std::printf(" in %.0f ms (read %.0f, components %.0f, extract %.0f, smooth %.0f%s, write %.0f, "
                "measure %.0f%s)\n",
                t.total, t.read, t.components, t.extract, t.smooth,
                options.decimate.active()
                    ? (", decimate " + std::to_string(long(t.decimate + 0.5))).c_str()
                    : "",
                t.write, t.measure,
                report ? (", report " + std::to_string(long(t.report + 0.5))).c_str() : "");
    std::printf("wrote %s%s\n", target.path.string().c_str(),
                target.folder ? (" (" + std::to_string(outputs.size()) + " files)").c_str() : "");
    if (!args.atlas.empty()) std::printf("atlas %s\n", args.atlas.c_str());
    if (!args.report.empty()) std::printf("report %s\n", args.report.c_str());
  }
  return 0;
}

}  // namespace

Subcommand add_mesh_command(CLI::App& app) {
  auto a = std::make_shared<MeshArgs>();
  CLI::App* cmd = app.add_subcommand(
      "mesh", "Mesh every part (connected component of each label) of a label map");
  cmd->add_option("input", a->input,
                  "volume file (.nii, .nii.gz, .nrrd, .seg.nrrd, .mha, .mrc, ...), DICOM SEG file "
                  "or DICOM folder")
      ->required();
  cmd->add_option("-o,--output", a->output,
                  "one file for all parts (scene.glb, .ply, .stl, .obj) or a folder ending in / "
                  "for one file per part")
      ->required();
  add_meshing_options(cmd, a->meshing);
  add_read_options(cmd, a->read);
  cmd->add_option("--color", a->color, "vertex colours: material or quality (radii ratio, blue 0 to green 1)")
      ->capture_default_str();
  cmd->add_option("--format", a->format, "file format for a folder output: stl, ply (default), obj, glb");
  cmd->add_option("--report", a->report, "write a JSON report to this file");
  cmd->add_option("--atlas", a->atlas,
                  "also write the conforming surface, one mesh whose triangles name their inside "
                  "and outside part, to this .ply or .glb file (needs --surfaces conforming)");
  cmd->add_option("--threads", a->threads, "worker threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--quantize", a->quantize,
               "glb: positions as 16-bit integers on one grid over the scene and normals as 8-bit "
               "(KHR_mesh_quantization), about half the file");
  cmd->add_flag("--quiet", a->quiet, "no progress bar and no summary");
  return {cmd, [a] { return run_mesh(*a); }};
}

}  // namespace segmesh::cli
