// Times segmesh's steps on one volume at a given thread count, best of N, and prints one JSON
// object: read, components, extraction by Marching Cubes and by Dual Contouring (every part, not
// smoothed), two HC iterations, the default smoothing, triangles. Each step is the pipeline's
// own function (pipeline.hpp). bench/compare_peers.sh runs it beside VTK
// (../shared/tools/peer_mesh.py).
//   segmesh_step_timing VOLUME THREADS [REPEATS]
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "segmesh/pipeline.hpp"
#include "segmesh_io/read_volume.hpp"

using namespace segmesh;
using Clock = std::chrono::steady_clock;

static double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: segmesh_step_timing VOLUME THREADS [REPEATS]\n");
    return 2;
  }
  const int threads = std::atoi(argv[2]);
  const int repeats = argc > 3 ? std::atoi(argv[3]) : 5;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  double read = 1e300, components = 1e300, mc = 1e300, dc = 1e300, hc = 1e300, smooth = 1e300;
  size_t triangles = 0;
  // The default options: Marching Cubes then smoothing, so no gradient normals are made.
  MeshingOptions o;
  for (int r = 0; r < repeats; ++r) {
    auto t = Clock::now();
    const Image image = read_volume(argv[1]);
    read = std::min(read, seconds_since(t));
    t = Clock::now();
    const PipelineParts parts = find_parts(image, o);
    components = std::min(components, seconds_since(t));
    t = Clock::now();
    Scene scene = extract_parts(image, parts, o);
    mc = std::min(mc, seconds_since(t));
    triangles = 0;
    for (const Part& p : scene.parts) triangles += p.mesh.triangle_count();
    Scene a = scene;
    t = Clock::now();
    smooth_scene(a, {.method = SmoothMethod::hc, .iterations = 2, .preserve_volume = false});
    hc = std::min(hc, seconds_since(t));
    t = Clock::now();
    smooth_scene(scene, default_smoothing());
    smooth = std::min(smooth, seconds_since(t));
    MeshingOptions d = o;
    d.method = Method::dual_contouring;
    t = Clock::now();
    const Scene dual = extract_parts(image, parts, d);
    dc = std::min(dc, seconds_since(t));
  }
  std::printf(
      "{\"threads\": %d, \"read_s\": %.6f, \"components_s\": %.6f, \"mc_s\": %.6f, \"dc_s\": %.6f, "
      "\"hc2_s\": %.6f, \"default_smooth_s\": %.6f, \"triangles\": %zu}\n",
      threads, read, components, mc, dc, hc, smooth, triangles);
}
