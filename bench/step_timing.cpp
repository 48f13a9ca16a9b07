// Times segmesh's steps on one volume at a given thread count and prints one JSON object: read,
// components, extraction by Marching Cubes and by Dual Contouring (every part, not smoothed, as
// the pipeline's default runs them: conforming where the parts touch, one by one where they do
// not), the conforming extractors on all the parts whether they touch or not (multi-label
// Marching Cubes and Dual Contouring, wall and CPU time, with a hash of each surface to tell
// whether a change kept the output byte for byte), the Dual Contouring / Marching Cubes ratios of
// both (issue 39's bound is 2), two HC iterations, the default smoothing, triangles. Each step is
// the pipeline's own function (pipeline.hpp), run REPEATS times back to back and timed at its
// best, the way ../shared/tools/peer_mesh.py times VTK's filters beside it in
// bench/compare_peers.sh: each run's result replaces the previous one, which is freed within the
// timed run.
//
// The steps are not interleaved (read, extract, smooth, read, extract, ...): then one step's
// allocations decide how glibc serves the next one's (its mapping threshold follows the blocks
// freed), and a change of Dual Contouring's table sizes made Marching Cubes on the phantom 15 %
// slower in the following round, with no change to Marching Cubes (docs/PERFORMANCE.md).
//   segmesh_step_timing VOLUME THREADS [REPEATS [extract]]
// With `extract` the smoothing steps are skipped (their times print as 0).
#include <tbb/global_control.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <optional>
#include <string_view>

#include "segmesh/multi_label_dual_contouring.hpp"
#include "segmesh/multi_label_marching_cubes.hpp"
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

static double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A conforming extraction's best wall time and best CPU time (of the process: every thread) over
// `repeats` calls, its last result left in `result`.
struct Timed {
  double wall = std::numeric_limits<double>::infinity();
  double cpu = std::numeric_limits<double>::infinity();
};
template <class Run>
static Timed best_of_conforming(int repeats, std::optional<LabelledSurface>& result, Run&& run) {
  Timed best;
  for (int r = 0; r < repeats; ++r) {
    const auto t = Clock::now();
    const double c = cpu_seconds();
    result = run();
    best.cpu = std::min(best.cpu, cpu_seconds() - c);
    best.wall = std::min(best.wall, std::chrono::duration<double>(Clock::now() - t).count());
  }
  return best;
}

// FNV-1a over a surface's positions, indices, sides and junction vertices.
static uint64_t surface_hash(const LabelledSurface& s) {
  uint64_t h = 0xcbf29ce484222325ULL;
  auto add = [&](const void* data, size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 0x100000001b3ULL;
  };
  add(s.mesh.positions.data(), s.mesh.positions.size() * sizeof(Vec3f));
  add(s.mesh.indices.data(), s.mesh.indices.size() * sizeof(uint32_t));
  add(s.sides.data(), s.sides.size() * sizeof(s.sides[0]));
  add(s.junction_vertices.data(), s.junction_vertices.size() * sizeof(uint32_t));
  return h;
}

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: segmesh_step_timing VOLUME THREADS [REPEATS [extract]]\n");
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
  // The conforming extractors on every kept part (what the pipeline runs where parts touch).
  std::optional<LabelledSurface> surface;
  const Grid& grid = image->grid();
  const Timed ml_mc = best_of_conforming(repeats, surface, [&] {
    return multi_label_marching_cubes(grid, parts->components, parts->kept, o.connectivity);
  });
  const uint64_t ml_mc_hash = surface_hash(*surface);
  const size_t ml_mc_triangles = surface->sides.size();
  const Timed ml_dc = best_of_conforming(repeats, surface, [&] {
    return multi_label_dual_contouring(grid, parts->components, parts->kept,
                                       {.connectivity = o.connectivity, .svd_eps = o.dc_svd_eps});
  });
  const uint64_t ml_dc_hash = surface_hash(*surface);
  const size_t ml_dc_triangles = surface->sides.size();
  surface.reset();
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
  const bool extract_only = argc > 4 && std::string_view(argv[4]) == "extract";
  const double hc =
      extract_only
          ? 0.0
          : smoothed({.method = SmoothMethod::hc, .iterations = 2, .preserve_volume = false});
  const double smooth = extract_only ? 0.0 : smoothed(default_smoothing());
  std::printf(
      "{\"threads\": %d, \"parts\": %zu, \"parts_touch\": %s, \"read_s\": %.6f, "
      "\"components_s\": %.6f, \"mc_s\": %.6f, \"dc_s\": %.6f, \"dc_over_mc\": %.2f, "
      "\"conforming_mc_s\": %.6f, \"conforming_mc_cpu_s\": %.6f, \"conforming_dc_s\": %.6f, "
      "\"conforming_dc_cpu_s\": %.6f, \"conforming_dc_over_mc\": %.2f, "
      "\"conforming_dc_over_mc_cpu\": %.2f, \"conforming_mc_triangles\": %zu, "
      "\"conforming_dc_triangles\": %zu, \"conforming_mc_hash\": \"%016llx\", "
      "\"conforming_dc_hash\": \"%016llx\", \"hc2_s\": %.6f, \"default_smooth_s\": %.6f, "
      "\"triangles\": %zu}\n",
      threads, parts->kept.size(), parts->touching ? "true" : "false", read, components, mc, dc,
      dc / mc, ml_mc.wall, ml_mc.cpu, ml_dc.wall, ml_dc.cpu, ml_dc.wall / ml_mc.wall,
      ml_dc.cpu / ml_mc.cpu, ml_mc_triangles, ml_dc_triangles, (unsigned long long)ml_mc_hash,
      (unsigned long long)ml_dc_hash, hc, smooth, triangles);
}
