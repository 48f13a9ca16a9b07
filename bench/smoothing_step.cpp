// Times the smoothing step alone (smooth_scene with the default smoothing) on one volume, for
// before/after comparisons of the smoothing code: wall and process CPU time of every repeat, on a
// fresh copy of the extracted scene each time (the copy is not timed). With DUMP, also writes every
// part's smoothed positions (float x, y, z, scene order) to that file, to compare builds.
//   segmesh_smoothing_step VOLUME THREADS REPEATS independent|conforming [DUMP]
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "segmesh/pipeline.hpp"
#include "segmesh_io/read_volume.hpp"

using namespace segmesh;

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr,
                 "usage: segmesh_smoothing_step VOLUME THREADS REPEATS independent|conforming "
                 "[DUMP]\n");
    return 2;
  }
  const int threads = std::atoi(argv[2]);
  const int repeats = std::max(1, std::atoi(argv[3]));
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  MeshingOptions o;
  const auto surfaces = parse_surfaces(argv[4]);
  if (!surfaces) return 2;
  o.surfaces = *surfaces;
  const Image image = read_volume(argv[1]);
  const PipelineParts parts = find_parts(image, o);
  const Scene extracted = extract_parts(image, parts, o);
  Scene scene;
  for (int r = 0; r < repeats; ++r) {
    scene = extracted;
    const std::clock_t c0 = std::clock();
    const auto t0 = std::chrono::steady_clock::now();
    smooth_scene(scene, default_smoothing());
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
    std::printf("wall_ms %.1f cpu_ms %.1f\n", 1e3 * wall, 1e3 * cpu);
  }
  if (argc > 5) {
    FILE* f = std::fopen(argv[5], "wb");
    if (!f) return 1;
    for (const Part& p : scene.parts)
      std::fwrite(p.mesh.positions.data(), sizeof(Vec3f), p.mesh.positions.size(), f);
    std::fclose(f);
  }
}
