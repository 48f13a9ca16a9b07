// How fast the viewer's Cancel takes effect: "Create mesh" (LoadJob on a volume already read, the
// viewer's own path) on a 512 x 512 x 400 volume, cancelled when a chosen step has reached a
// chosen fraction, and the time from cancel() to the job's end. Also records how the progress
// moved before the cancel (how many distinct fractions the window could have shown).
// Inputs: the phantom at 512 x 512 x 400 (0.197 x 0.197 x 1 mm: ten parts, one large bone) and
// one ball filling that grid (a single part of 80 M voxels).
//   segmesh_cancel_latency [THREADS]
#include <tbb/global_control.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>
#include <string>
#include <thread>

#include "segmesh/phantom.hpp"
#include "segmesh_viewer/load_job.hpp"

using namespace segmesh;
using namespace std::chrono;

namespace {

std::shared_ptr<const Image> image_of(LabelVolume v, const std::string& name) {
  auto image = std::make_shared<Image>();
  image->path = name;
  image->voxel_type = "uint8";
  Volume<uint8_t> bytes;
  bytes.grid = v.grid;
  bytes.voxels.assign(v.voxels.begin(), v.voxels.end());
  image->volume = std::move(bytes);
  return image;
}

LabelVolume ball(std::array<int64_t, 3> n) {
  LabelVolume v;
  v.grid.dims = n;
  v.grid.spacing = {0.197, 0.197, 1.0};
  v.voxels.assign(v.grid.voxel_count(), 0);
  const double cx = (n[0] - 1) / 2.0, cy = (n[1] - 1) / 2.0, cz = (n[2] - 1) / 2.0;
  for (int64_t k = 0; k < n[2]; ++k)
    for (int64_t j = 0; j < n[1]; ++j)
      for (int64_t i = 0; i < n[0]; ++i) {
        const double x = (i - cx) / cx, y = (j - cy) / cy, z = (k - cz) / cz;
        if (x * x + y * y + z * z < 0.9) v.at(i, j, k) = 1;
      }
  return v;
}

struct Result {
  bool cancelled = false;
  double latency_ms = 0;
  int fractions_seen = 0;
  double fraction_at_cancel = 0;
};

// Runs the job and cancels once `step` reports at least `at`; polls as a frame loop would.
Result cancel_during(std::shared_ptr<const Image> image, Method method, const std::string& step,
                     double at) {
  viewer::LoadJob job;
  MeshingOptions o;
  o.method = method;
  job.start({{}, image, o});
  std::set<double> seen;
  Result r;
  for (;;) {
    const viewer::JobStatus s = job.status();
    if (!s.running) break;
    if (s.step == step) {
      seen.insert(s.fraction);
      if (s.fraction >= at) {
        r.fraction_at_cancel = s.fraction;
        const auto t0 = steady_clock::now();
        job.cancel();
        job.wait();
        r.latency_ms = duration<double, std::milli>(steady_clock::now() - t0).count();
        break;
      }
    }
    std::this_thread::sleep_for(milliseconds(2));
  }
  const auto outcome = job.take_outcome();
  r.cancelled = outcome && outcome->kind == viewer::LoadOutcome::Kind::cancelled;
  r.fractions_seen = int(seen.size());
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const int threads = argc > 1 ? std::atoi(argv[1]) : 2;
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  const std::array<int64_t, 3> size{512, 512, 400};
  const auto phantom = image_of(make_phantom({.size = size, .spacing = {0.197, 0.197, 1.0}}),
                                "phantom 512x512x400");
  const auto single = image_of(ball(size), "ball 512x512x400");
  std::printf("| volume | method | cancelled in step | at | fractions shown before | cancelled | "
              "cancel to end (ms) |\n| --- | --- | --- | ---: | ---: | --- | ---: |\n");
  for (const auto& image : {phantom, single}) {
    for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
      const std::string extract = method == Method::dual_contouring ? "dual contouring"
                                                                   : "marching cubes";
      for (const auto& [step, at] : {std::pair<std::string, double>{"components", 0.3},
                                     {extract, 0.3}, {extract, 0.7}, {"smoothing", 0.3},
                                     {"measuring", 0.3}}) {
        const Result r = cancel_during(image, method, step, at);
        std::printf("| %s | %s | %s | %.2f | %d | %s | %.1f |\n", image->path.c_str(),
                    extract.c_str(), step.c_str(), r.fraction_at_cancel, r.fractions_seen,
                    r.cancelled ? "yes" : "NO", r.latency_ms);
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
