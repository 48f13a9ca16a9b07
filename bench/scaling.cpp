// How the cost grows with the volume size and the thread count (docs/PERFORMANCE.md): the phantom
// at N x N x (N * 203 / 512) voxels over the same anatomy (spacing scaled so the extent stays the
// reference's 101 x 101 x 406 mm), meshed at 1 and 2 threads. Best of 3 per cell.
//   segmesh_scaling [N...]    (default 128 256 384 512 768)
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"

using namespace segmesh;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  std::vector<int64_t> sizes;
  for (int a = 1; a < argc; ++a) sizes.push_back(std::atoll(argv[a]));
  if (sizes.empty()) sizes = {128, 256, 384, 512, 768};
  std::printf("| voxels | threads | triangles | components + MC (ms) | DC (ms) | HC x2 (ms) | default smoothing (ms) | MC ns / voxel |\n");
  std::printf("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  for (int64_t n : sizes) {
    const int64_t nz = std::max<int64_t>(8, n * 203 / 512);
    PhantomOptions po;
    po.size = {n, n, nz};
    po.spacing = {0.197 * 512 / double(n), 0.197 * 512 / double(n), 2.0 * 203 / double(nz)};
    Image image;
    image.path = "phantom";
    image.voxel_type = "uint8";
    image.volume = make_phantom(po);
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
      double mc = 1e300, dc = 1e300, hc = 1e300, smooth = 1e300;
      size_t triangles = 0;
      for (int r = 0; r < 3; ++r) {
        MeshingOptions o;
        o.smooth = {};
        PipelineStats s;
        Scene scene = build_scene(image, o, null_progress(), &s);
        mc = std::min(mc, s.components_ms + s.extract_ms);
        triangles = 0;
        for (const Part& p : scene.parts) triangles += p.mesh.triangle_count();
        Scene a = scene;
        auto t = Clock::now();
        smooth_scene(a, {.method = SmoothMethod::hc, .iterations = 2, .preserve_volume = false});
        hc = std::min(hc, std::chrono::duration<double, std::milli>(Clock::now() - t).count());
        t = Clock::now();
        smooth_scene(scene, default_smoothing());
        smooth = std::min(smooth, std::chrono::duration<double, std::milli>(Clock::now() - t).count());
        o.method = Method::dual_contouring;
        build_scene(image, o, null_progress(), &s);
        dc = std::min(dc, s.components_ms + s.extract_ms);
      }
      const double voxels = double(n) * double(n) * double(nz);
      std::printf("| %lld x %lld x %lld | %d | %zu | %.0f | %.0f | %.0f | %.0f | %.2f |\n", (long long)n,
                  (long long)n, (long long)nz, threads, triangles, mc, dc, hc, smooth, mc * 1e6 / voxels);
      std::fflush(stdout);
    }
  }
}
