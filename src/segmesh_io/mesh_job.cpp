#include "segmesh_io/mesh_job.hpp"

#include <tbb/task_group.h>

#include "segmesh/error.hpp"
#include "segmesh_io/atlas_writer.hpp"
#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh {

namespace fs = std::filesystem;

namespace {

// The files written, as reported: in the reported folder when written into another one.
std::vector<std::string> reported_outputs(const std::vector<fs::path>& written, const MeshJob& job) {
  std::vector<std::string> out;
  const MeshTarget& reported = job.request.target;
  for (const fs::path& p : written) {
    out.push_back((reported.folder ? reported.path / p.filename() : reported.path).string());
  }
  return out;
}

}  // namespace

MeshJobResult run_mesh_job(Image& image, const MeshJob& job, Progress& progress,
                           MeshTimings& t, std::chrono::steady_clock::time_point start) {
  const ReportedRequest& request = job.request;
  const MeshingOptions& options = request.options;
  const MeshTarget& target = job.write_to;
  const bool report = !job.report.empty();
  MeshJobResult r;
  // The positions before smoothing and the meshes before decimation are kept for the report only.
  const bool moved = options.smooth.method != SmoothMethod::none || options.decimate.active();
  ExtractedPositions extracted;
  r.scene = build_scene_releasing(image, options, progress, &r.pipeline,
                                  report && moved ? &extracted : nullptr);
  const Scene& scene = r.scene;
  t.components = r.pipeline.components_ms;
  t.extract = r.pipeline.extract_ms;
  t.smooth = r.pipeline.smooth_ms;
  t.decimate = r.pipeline.decimate_ms;
  // Part files are named after the parts, known only now; refused before anything is written.
  if (target.folder && !request.atlas.empty()) {
    for (const fs::path& p : part_file_paths(scene, target.path, target.format)) {
      if (same_path(p, request.atlas)) {
        throw Error(request.atlas + ": --atlas names the file of part " + p.stem().string() +
                    " in the -o folder; choose another name");
      }
    }
  }

  // The parts' measures run beside the write (writing is mostly serial encoding and the kernel's
  // copy), and not at all when neither asked for nor reported. The extracted positions go as soon
  // as they are measured.
  tbb::task_group measuring;
  if (job.measure || report) {
    measuring.run([&] {
      r.measures = measure_scene(scene, {.quality = report,
                                         .contacts = report,
                                         .extracted = report && moved ? &extracted : nullptr});
      extracted = {};
    });
  }
  progress.step("writing");
  auto step = std::chrono::steady_clock::now();
  std::vector<fs::path> written;
  try {
    if (target.folder) {
      written = write_parts(scene, target.path, target.format, request.write);
    } else {
      write_scene(scene, target.path, target.format, request.write);
      written.push_back(target.path);
    }
    r.outputs = reported_outputs(written, job);
    if (!request.atlas.empty()) {
      write_atlas(scene, request.atlas);
      r.outputs.push_back(request.atlas);
    }
  } catch (...) {
    measuring.wait();
    throw;
  }
  t.write = ms_since(step);
  step = std::chrono::steady_clock::now();
  measuring.wait();
  t.measure = ms_since(step);
  r.say_surfaces_note = request.surfaces_note && r.pipeline.parts_touch;
  if (report) {
    ReportedRequest reported = request;
    if (!r.say_surfaces_note) reported.surfaces_note.reset();
    write_mesh_report(job.report, image, reported, t, start, r.pipeline, scene, r.measures,
                      r.outputs);
  }
  t.total = ms_since(start);
  return r;
}

}  // namespace segmesh
