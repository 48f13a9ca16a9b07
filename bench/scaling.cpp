// How the cost grows with the volume size and the thread count (docs/PERFORMANCE.md): the phantom
// at N x N x (N * 203 / 512) voxels over the same anatomy (spacing scaled so the extent stays the
// reference's 101 x 101 x 406 mm), each step through the pipeline's own functions at 1 and 2
// threads. Best of 3 per cell.
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

static double ms_since(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

int main(int argc, char** argv) {
  std::vector<int64_t> sizes;
  for (int a = 1; a < argc; ++a) sizes.push_back(std::atoll(argv[a]));
  if (sizes.empty()) sizes = {128, 256, 384, 512, 768};
  std::printf("| voxels | threads | triangles | components (ms) | MC (ms) | DC (ms) | HC x2 (ms) | default smoothing (ms) | components + MC, ns / voxel | MC, ns / triangle |\n");
  std::printf("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  for (int64_t n : sizes) {
    const int64_t nz = std::max<int64_t>(8, n * 203 / 512);
    PhantomOptions po;
    po.size = {n, n, nz};
    po.spacing = {0.197 * 512 / double(n), 0.197 * 512 / double(n), 2.0 * 203 / double(nz)};
    Image image;
    image.path = "phantom";
    image.voxel_type = "uint8";
    LabelVolume labels = make_phantom(po);
    Volume<uint8_t> bytes{labels.grid, std::vector<uint8_t>(labels.voxels.begin(), labels.voxels.end())};
    labels = {};
    image.volume = std::move(bytes);  // as read from a uint8 file
    const MeshingOptions o;  // the default: Marching Cubes, then the default smoothing
    MeshingOptions dual = o;
    dual.method = Method::dual_contouring;
    for (int threads : {1, 2}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
      double components = 1e300, mc = 1e300, dc = 1e300, hc = 1e300, smooth = 1e300;
      size_t triangles = 0;
      for (int r = 0; r < 3; ++r) {
        auto t = Clock::now();
        const PipelineParts parts = find_parts(image, o);
        components = std::min(components, ms_since(t));
        t = Clock::now();
        Scene scene = extract_parts(image, parts, o);
        mc = std::min(mc, ms_since(t));
        triangles = 0;
        for (const Part& p : scene.parts) triangles += p.mesh.triangle_count();
        Scene a = scene;
        t = Clock::now();
        smooth_scene(a, {.method = SmoothMethod::hc, .iterations = 2, .preserve_volume = false});
        hc = std::min(hc, ms_since(t));
        t = Clock::now();
        smooth_scene(scene, default_smoothing());
        smooth = std::min(smooth, ms_since(t));
        t = Clock::now();
        const Scene d = extract_parts(image, parts, dual);
        dc = std::min(dc, ms_since(t));
      }
      const double voxels = double(n) * double(n) * double(nz);
      std::printf("| %lld x %lld x %lld | %d | %zu | %.1f | %.1f | %.0f | %.0f | %.0f | %.2f | %.1f |\n",
                  (long long)n, (long long)n, (long long)nz, threads, triangles, components, mc, dc, hc,
                  smooth, (components + mc) * 1e6 / voxels, mc * 1e6 / double(triangles));
      std::fflush(stdout);
    }
  }
}
