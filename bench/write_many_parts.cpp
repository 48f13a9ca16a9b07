// Times the per-part work after meshing on one volume (issue 40: many-part maps): every scene
// writer (GLB, GLB quantized, PLY, OBJ, STL, and with FOLDER one PLY file per part), the parts'
// measures and the report, each on the same scene built once with the default options (the
// build is not timed). Prints, per step, the wall time of every repeat and microseconds per part.
//   segmesh_write_many_parts VOLUME OUT_DIR [THREADS [REPEATS [STEPS]]]
// e.g. a 32^3 map of 256 random labels (31 000 parts): segmesh_write_many_parts r32_255.nii.gz
// /tmp/wmp 2 3. STEPS, comma-separated, picks steps among glb, glbq (quantized), ply, obj, stl,
// folder (write_parts, one PLY file per part: 31 000 files there), measure and report (which
// needs measure); the default is all but folder.
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

#include "segmesh/pipeline.hpp"
#include "segmesh/scene_measures.hpp"
#include "segmesh_io/mesh_report.hpp"
#include "segmesh_io/read_volume.hpp"
#include "segmesh_io/write_mesh.hpp"

using namespace segmesh;
namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: segmesh_write_many_parts VOLUME OUT_DIR [THREADS [REPEATS [FOLDER]]]\n");
    return 2;
  }
  const fs::path out = argv[2];
  const int threads = argc > 3 ? std::atoi(argv[3]) : 2;
  const int repeats = argc > 4 ? std::max(1, std::atoi(argv[4])) : 3;
  const std::string steps = "," + std::string(argc > 5 ? argv[5] : "glb,glbq,ply,obj,stl,measure,report") + ",";
  const auto run = [&](const char* step) { return steps.find("," + std::string(step) + ",") != std::string::npos; };
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  fs::create_directories(out);

  Image image = read_volume(argv[1]);
  const MeshingOptions options = resolve_meshing_options(MeshingOptions{});
  ExtractedPositions extracted;
  PipelineStats stats;
  const Scene scene = build_scene(image, options, null_progress(), &stats, &extracted);
  size_t triangles = 0;
  for (const Part& p : scene.parts) triangles += p.mesh.triangle_count();
  std::printf("%s: %zu parts, %zu triangles, %d threads\n", argv[1], scene.parts.size(), triangles,
              threads);

  SceneMeasures measures;
  const auto time = [&](const char* what, const std::function<void()>& step) {
    std::printf("%-14s", what);
    double best = 1e300;
    for (int r = 0; r < repeats; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      step();
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      best = std::min(best, ms);
      std::printf(" %9.1f ms", ms);
    }
    std::printf("   best %6.2f us/part\n", 1e3 * best / double(std::max<size_t>(1, scene.parts.size())));
    std::fflush(stdout);
  };
  if (run("glb")) time("glb", [&] { write_scene(scene, out / "scene.glb", MeshFormat::glb); });
  if (run("glbq")) {
    time("glb quantized", [&] { write_scene(scene, out / "scene_q.glb", MeshFormat::glb, {.quantize = true}); });
  }
  if (run("ply")) time("ply", [&] { write_scene(scene, out / "scene.ply", MeshFormat::ply); });
  if (run("obj")) time("obj", [&] { write_scene(scene, out / "scene.obj", MeshFormat::obj); });
  if (run("stl")) time("stl", [&] { write_scene(scene, out / "scene.stl", MeshFormat::stl); });
  if (run("folder")) {
    time("ply per part", [&] {
      fs::remove_all(out / "parts");
      write_parts(scene, out / "parts", MeshFormat::ply);
    });
  }
  if (!run("measure")) return 0;
  time("measure", [&] { measures = measure_scene(scene, {.extracted = &extracted}); });
  ReportedRequest request{.options = options,
                          .target = {.path = out / "scene.glb", .format = MeshFormat::glb}};
  if (run("report")) time("report", [&] {
    MeshTimings t;
    write_mesh_report(out / "report.json", image, request, t, std::chrono::steady_clock::now(),
                      stats, scene, measures, {(out / "scene.glb").string()});
  });
}
