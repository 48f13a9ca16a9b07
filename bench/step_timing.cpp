// Times segmesh's steps on one volume at a given thread count and prints one JSON object: read,
// components, extraction by Marching Cubes and by Dual Contouring (every part, not smoothed), two
// HC iterations, the default smoothing, triangles. Each step is the pipeline's own function
// (pipeline.hpp), run REPEATS times back to back and timed at its best, the way
// ../shared/tools/peer_mesh.py times VTK's filters beside it in bench/compare_peers.sh: each run's
// result replaces the previous one, which is freed within the timed run.
//
// The steps are not interleaved (read, extract, smooth, read, extract, ...): then one step's
// allocations decide how glibc serves the next one's (its mapping threshold follows the blocks
// freed), and a change of Dual Contouring's table sizes made Marching Cubes on the phantom 15 %
// slower in the following round, with no change to Marching Cubes (docs/PERFORMANCE.md).
//   segmesh_step_timing VOLUME THREADS [REPEATS]
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>

#include "segmesh/pipeline.hpp"
#include "segmesh_io/read_volume.hpp"

using namespace segmesh;
using Clock = std::chrono::steady_clock;

// The best time of `repeats` calls of run(), its last result left in `result`.
template <class T, class Run>
static double best_of(int repeats, std::optional<T>& result, Run&& run) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    result = run();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t).count());
  }
  return best;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: segmesh_step_timing VOLUME THREADS [REPEATS]\n");
    return 2;
  }
  const int threads = std::atoi(argv[2]);
  const int repeats = std::max(1, argc > 3 ? std::atoi(argv[3]) : 5);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  // The default options: Marching Cubes then smoothing, so no gradient normals are made.
  const MeshingOptions o;
  MeshingOptions d = o;
  d.method = Method::dual_contouring;

  std::optional<Image> image;
  const double read = best_of(repeats, image, [&] { return read_volume(argv[1]); });
  std::optional<PipelineParts> parts;
  const double components = best_of(repeats, parts, [&] { return find_parts(*image, o); });
  std::optional<Scene> mc_scene;
  const double mc = best_of(repeats, mc_scene, [&] { return extract_parts(*image, *parts, o); });
  size_t triangles = 0;
  for (const Part& p : mc_scene->parts) triangles += p.mesh.triangle_count();
  std::optional<Scene> dual;
  const double dc = best_of(repeats, dual, [&] { return extract_parts(*image, *parts, d); });
  dual.reset();
  // Each smoothing run starts from the extracted scene; the copy is not timed.
  auto smoothed = [&](const SmoothOptions& s) {
    std::optional<Scene> result;
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < repeats; ++r) {
      Scene copy = *mc_scene;
      const auto t = Clock::now();
      smooth_scene(copy, s);
      result = std::move(copy);
      best = std::min(best, std::chrono::duration<double>(Clock::now() - t).count());
    }
    return best;
  };
  const double hc =
      smoothed({.method = SmoothMethod::hc, .iterations = 2, .preserve_volume = false});
  const double smooth = smoothed(default_smoothing());
  std::printf(
      "{\"threads\": %d, \"read_s\": %.6f, \"components_s\": %.6f, \"mc_s\": %.6f, \"dc_s\": %.6f, "
      "\"hc2_s\": %.6f, \"default_smooth_s\": %.6f, \"triangles\": %zu}\n",
      threads, read, components, mc, dc, hc, smooth, triangles);
}
