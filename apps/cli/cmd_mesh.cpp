// segmesh mesh INPUT -o OUTPUT [options]: the main job. Reads a label map (or a grey-value volume
// with --iso), splits it into parts, extracts each (Marching Cubes or Dual Contouring), writes the
// meshes, the conforming surface as an atlas (--atlas) and a report. Every check that can fail on
// the user's input runs before the long work starts.
#include <tbb/task_group.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <system_error>

#include "cli_common.hpp"
#include "commands.hpp"
#include "mesh_report.hpp"
#include "meshing_args.hpp"
#include "progress_bar.hpp"
#include "segmesh/error.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/atlas_writer.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/mesh_format.hpp"
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

// Whether two paths name the same file or folder, however spelled ("a.ply", "./a.ply"); neither
// needs to exist.
bool same_path(const fs::path& a, const fs::path& b) {
  std::error_code e1, e2;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a), e1);
  const fs::path cb = fs::weakly_canonical(fs::absolute(b), e2);
  return e1 || e2 ? a == b : ca == cb;
}

// Throws when the outputs of `option` and `other_option` are the same file.
void refuse_same_file(const std::string& path, const char* option, const fs::path& other,
                      const char* other_option) {
  if (same_path(path, other)) {
    throw Error(path + ": " + option + " and " + other_option +
                " name the same file; choose another name");
  }
}

// --atlas: the conforming surface, so conforming surfaces (the default for label maps with
// Marching Cubes); a .ply or .glb file in an existing folder (or the -o folder, made before the
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

nlohmann::json options_json(const MeshArgs& a, const MeshingOptions& resolved,
                            const MeshTarget& out) {
  nlohmann::json j = meshing_json(resolved, a.meshing.label_names);
  j["format"] = extension(out.format);
  j["quantize"] = a.quantize;
  j["output"] = out.path.string();
  j["per_part_files"] = out.folder;
  j["atlas"] = a.atlas.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.atlas);
  j["threads"] = a.threads;
  j["color"] = a.color;
  return j;
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

  Timings t;
  ProgressBar progress(!args.quiet);
  progress.step("reading");
  auto step = std::chrono::steady_clock::now();
  Image image = read_input(args.input, args.read);
  t.read = ms_since(step);

  PipelineStats pipeline;
  const bool report = !args.report.empty();
  // The positions before smoothing and the meshes before decimation are kept for the report only.
  const bool moved = options.smooth.method != SmoothMethod::none || options.decimate.active();
  ExtractedPositions extracted;
  const Scene scene = build_scene_releasing(image, options, progress, &pipeline,
                                            report && moved ? &extracted : nullptr);
  t.components = pipeline.components_ms;
  t.extract = pipeline.extract_ms;
  t.smooth = pipeline.smooth_ms;
  t.decimate = pipeline.decimate_ms;
  // Part files are named after the parts, known only now; refused before anything is written.
  if (target.folder && !args.atlas.empty()) {
    for (const fs::path& p : part_file_paths(scene, target.path, target.format)) {
      if (same_path(p, args.atlas)) {
        throw Error(args.atlas + ": --atlas names the file of part " + p.stem().string() +
                    " in the -o folder; choose another name");
      }
    }
  }

  // The parts' measures are for the summary table and the report only (the topology checks for
  // the table; quality, volume change and smoothing deviation for the report too). They run
  // beside the write (writing is mostly serial encoding and the kernel's copy), and not at all
  // with --quiet and no report. The extracted positions go as soon as they are measured.
  SceneMeasures measures;
  tbb::task_group measuring;
  if (!args.quiet || report) {
    measuring.run([&] {
      measures = measure_scene(scene, {.quality = report,
                                       .contacts = report,
                                       .extracted = report && moved ? &extracted : nullptr});
      extracted = {};
    });
  }
  progress.step("writing");
  step = std::chrono::steady_clock::now();
  std::vector<std::string> outputs;
  try {
    if (target.folder) {
      for (const fs::path& p : write_parts(scene, target.path, target.format, write_options)) {
        outputs.push_back(p.string());
      }
    } else {
      write_scene(scene, target.path, target.format, write_options);
      outputs.push_back(target.path.string());
    }
    if (!args.atlas.empty()) {
      write_atlas(scene, args.atlas);
      outputs.push_back(args.atlas);
    }
  } catch (...) {
    measuring.wait();
    throw;
  }
  t.write = ms_since(step);
  step = std::chrono::steady_clock::now();
  measuring.wait();
  t.measure = ms_since(step);
  progress.finish();
  // Said once, after the progress bar, when parts touch.
  const bool say = note && pipeline.parts_touch;
  if (say && !args.quiet) std::fprintf(stderr, "note: %s\n", note->c_str());
  if (report) {
    step = std::chrono::steady_clock::now();
    nlohmann::json reported_options = options_json(args, options, target);
    reported_options["surfaces_note"] = say ? nlohmann::json(*note) : nlohmann::json(nullptr);
    nlohmann::json json = mesh_report(image, reported_options, t, pipeline,
                                      scene, measures, outputs);
    t.report = ms_since(step);
    // The total as the report is written: everything but the file write and the summary below.
    t.total = ms_since(start);
    json["timings_ms"]["report"] = t.report;
    json["timings_ms"]["other"] = t.total - t.steps();
    json["timings_ms"]["total"] = t.total;
    AtomicFile file(args.report);
    file.stream() << json.dump(2) << '\n';
    file.commit();
  }
  t.total = ms_since(start);
  if (!args.quiet) {
    std::printf("%s", summary_table(scene, measures.parts).c_str());
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
  cmd->add_option("input", a->input, "volume file (.nii, .nii.gz, .nrrd, .seg.nrrd, .mha, .mrc, ...) or DICOM folder")
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
