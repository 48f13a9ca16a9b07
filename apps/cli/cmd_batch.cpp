// segmesh batch INPUTS... -o OUT/ [options]: a cohort, one case after the other, each meshed as
// `segmesh mesh` would (the library's case runner, segmesh_io/case_runner.hpp) into OUT/CASE/
// (meshes and report.json), with OUT/summary.csv rewritten after every case. A failed case is
// recorded and the rest go on; a finished case is skipped on the next run unless --force;
// --shard I/N takes a disjoint slice for job arrays. docs/COHORTS.md has the details.
//
// Exit codes: 0 every case ok or skipped, 1 some case failed, 2 a bad argument (nothing written).
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "cli_common.hpp"
#include "commands.hpp"
#include "meshing_args.hpp"
#include "segmesh/error.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/case_runner.hpp"
#include "segmesh_io/case_summary.hpp"
#include "segmesh_io/cohort_inputs.hpp"

namespace segmesh::cli {

namespace fs = std::filesystem;

namespace {

struct BatchArgs {
  std::vector<std::string> inputs;
  std::string output;
  MeshingArgs meshing;
  std::string format = "glb";
  bool per_part = false;
  bool quantize = false;
  std::string color = "material";
  int threads = 0;
  std::string shard;
  bool force = false;
  bool allow_external_data = false;
  bool quiet = false;
  ReadArgs read;
};

// Every case this run takes, checked: its options resolved, before OUT is touched.
struct Plan {
  fs::path out;  // OUT without a trailing "/"
  std::vector<CaseRequest> cases;
  Shard shard;
  size_t total = 0;  // cases in the whole cohort
};

Plan plan_batch(const BatchArgs& a) {
  Plan plan;
  plan.out = cohort_output_folder(a.output);
  if (!a.shard.empty()) plan.shard = parse_shard(a.shard);
  CohortSettings settings{.label_names_file = a.meshing.label_names,
                          .format = cohort_format(a.format),
                          .per_part = a.per_part,
                          .write = {.quantize = a.quantize},
                          .color = a.color,
                          .threads = a.threads,
                          .read = {.max_voxels = a.read.max_voxels,
                                   .allow_external_data = a.allow_external_data},
                          .force = a.force};
  check_cohort_settings(settings);
  settings.defaults = meshing_request(a.meshing);
  resolve_meshing_options(settings.defaults);
  const std::vector<CohortCase> cohort = expand_cohort_inputs(a.inputs, plan.out);
  plan.total = cohort.size();
  for (size_t i = 0; i < cohort.size(); ++i) {
    if (!plan.shard.takes(i)) continue;
    CaseRequest q = case_request(cohort[i], plan.out, settings);
    const std::string name = q.name;
    q.read.warn = [name](const std::string& message) {
      std::fprintf(stderr, "segmesh: warning: %s: %s\n", name.c_str(), message.c_str());
    };
    plan.cases.push_back(std::move(q));
  }
  if (fs::exists(plan.out) && !fs::is_directory(plan.out)) {
    throw Error(a.output + ": exists and is not a folder; -o names the output folder");
  }
  if (!fs::exists(plan.out)) require_parent_folder(plan.out);
  return plan;
}

int run_batch(const BatchArgs& a) {
  const Plan plan = plan_batch(a);
  std::error_code ec;
  if (!fs::create_directories(plan.out, ec) && ec) {
    throw Error(a.output + ": cannot create the folder (" + ec.message() + ")");
  }
  const auto threads = limit_threads(a.threads);
  const fs::path summary = plan.out / summary_file_name(plan.shard.index, plan.shard.count);
  std::vector<CaseResult> rows;
  for (const CaseRequest& q : plan.cases) rows.push_back({.name = q.name, .input = q.input.string()});
  write_case_summary(summary, rows);
  int failed = 0;
  for (size_t i = 0; i < plan.cases.size(); ++i) {
    rows[i] = run_case(plan.cases[i]);
    write_case_summary(summary, rows);
    failed += rows[i].status == CaseStatus::failed;
    if (a.quiet) continue;
    const CaseResult& r = rows[i];
    std::fprintf(stderr, "[%zu/%zu] %s %s %.1f s%s%s\n", i + 1, plan.cases.size(), r.name.c_str(),
                 std::string(case_status_name(r.status)).c_str(), r.seconds,
                 r.error.empty() ? "" : ": ", r.error.c_str());
  }
  if (!a.quiet) {
    std::fprintf(stderr, "%zu cases (%d failed) of %zu%s; summary %s\n", plan.cases.size(), failed,
                 plan.total, plan.shard.count > 1 ? (" (shard " + a.shard + ")").c_str() : "",
                 summary.string().c_str());
  }
  return failed > 0 ? 1 : 0;
}

}  // namespace

Subcommand add_batch_command(CLI::App& app) {
  auto a = std::make_shared<BatchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "batch",
      "Mesh a cohort: every case into OUT/CASE/ (meshes, report.json) and OUT/summary.csv; "
      "resumes, isolates failures, shards (docs/COHORTS.md)");
  cmd->add_option("inputs", a->inputs,
                  "volume files, folders of them (or of DICOM series), globs, or a .csv/.tsv "
                  "manifest with a path column and per-case option columns")
      ->required();
  cmd->add_option("-o,--output", a->output, "output folder: OUT/CASE/ per case, OUT/summary.csv")
      ->required();
  add_meshing_options(cmd, a->meshing);
  add_read_options(cmd, a->read);
  cmd->add_option("--format", a->format, "mesh format of each case's scene file: glb, ply, stl, obj")
      ->capture_default_str();
  cmd->add_flag("--per-part", a->per_part, "one mesh file per part in OUT/CASE/ instead of one scene file");
  cmd->add_flag("--quantize", a->quantize, "glb: KHR_mesh_quantization, about half the file");
  cmd->add_option("--color", a->color, "vertex colours: material or quality")->capture_default_str();
  cmd->add_option("--threads", a->threads, "worker threads per case (0: all cores)")
      ->capture_default_str();
  cmd->add_option("--shard", a->shard,
                  "I/N: run only the cases whose index modulo N is I-1 (job arrays); writes "
                  "OUT/summary-I-of-N.csv");
  cmd->add_flag("--force", a->force, "redo cases already finished in OUT");
  cmd->add_flag("--allow-external-data", a->allow_external_data,
                "read detached data files (NRRD data file, MetaImage ElementDataFile) outside "
                "their header's folder");
  cmd->add_flag("--quiet", a->quiet, "no progress line per case");
  return {cmd, [a] { return run_batch(*a); }};
}

}  // namespace segmesh::cli
