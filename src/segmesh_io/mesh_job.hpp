// run_mesh_job: one meshing run from a volume in memory to its files, the part of `segmesh mesh`
// that the batch case runner (case_runner.hpp) and the Python package share. It builds the scene
// through the one pipeline (build_scene_releasing), measures it with measure_scene beside the
// write, writes the meshes (write_scene or write_parts), the atlas (write_atlas) and the JSON
// report (mesh_report.hpp).
//
// Guarantees: every file is written atomically; an atlas that would be one of the part files is
// refused before anything is written. The measures are taken only when asked (`measure`) or for
// the report, and the positions as extracted are kept only for the report.
// Errors: segmesh::Error from the pipeline and the writers; Cancelled from `progress`.
#pragma once

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/mesh_report.hpp"

namespace segmesh {

struct MeshJob {
  // What the report records: the resolved options, the target, the write options, the atlas, ...
  // request.surfaces_note is surfaces_note(the request); the report says it only when parts touch.
  ReportedRequest request;
  std::filesystem::path report;  // "" for none
  bool measure = true;           // measure the parts even without a report (a summary table)
  // Where the meshes are written: request.target, or the same file names in a temporary folder
  // that the caller renames to the reported place afterwards (the case runner's atomic folder).
  MeshTarget write_to;
};

struct MeshJobResult {
  Scene scene;
  SceneMeasures measures;  // empty unless measured
  PipelineStats pipeline;
  std::vector<std::string> outputs;  // the files written, as reported
  bool say_surfaces_note = false;    // request.surfaces_note applies: parts touch
};

// Meshes `image` (its voxels are freed once extraction is done) and writes the job's files.
// `timings` comes with the read time and gets every other step's; `start` is when the run
// started (for the report's total).
MeshJobResult run_mesh_job(Image& image, const MeshJob& job, Progress& progress,
                           MeshTimings& timings, std::chrono::steady_clock::time_point start);

}  // namespace segmesh
