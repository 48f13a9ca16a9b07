// The extraction dispatch as a front end meets it: progress moves while one large part is
// extracted (every method, with and without volume smoothing), and a cancel reaches inside the
// part's extraction: the work stops at its next block, not at the end of the part.
#include "segmesh/extract_part.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <map>
#include <mutex>
#include <set>
#include <string>

#include "segmesh/error.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"

namespace segmesh {
namespace {

// One ball of label 1 filling most of an n^3 volume: a single large part.
Image ball_image(int64_t n) {
  LabelVolume v;
  v.grid.dims = {n, n, n};
  v.grid.spacing = {0.5, 0.5, 0.8};
  v.voxels.assign(v.grid.voxel_count(), 0);
  const double c = (n - 1) / 2.0, r = 0.45 * n;
  for (int64_t k = 0; k < n; ++k)
    for (int64_t j = 0; j < n; ++j)
      for (int64_t i = 0; i < n; ++i) {
        const double x = i - c, y = j - c, z = k - c;
        if (x * x + y * y + z * z < r * r) v.at(i, j, k) = 1;
      }
  Image image;
  image.path = "ball.nii.gz";
  image.voxel_type = "uint8";
  image.volume = std::move(v);
  return image;
}

// Records the steps and fractions a run reports; cancels once `cancel_step` reports at least
// `cancel_at`, then counts the updates that still arrive.
class Recorder : public Progress {
 public:
  std::string cancel_step;
  double cancel_at = 2;  // never, by default

  void step(std::string_view name) override {
    std::lock_guard lock(mutex_);
    current_ = name;
    steps.insert(current_);
  }
  void update(double fraction) override {
    std::lock_guard lock(mutex_);
    if (cancelled_) {
      ++updates_after_cancel;
      return;
    }
    if (current_ == extraction_step()) inside_fractions.insert(fraction);
    if (current_ == cancel_step && fraction >= cancel_at) cancelled_ = true;
  }
  bool cancelled() const override {
    std::lock_guard lock(mutex_);
    return cancelled_;
  }
  std::string extraction_step() const { return extraction_step_; }
  void set_extraction_step(std::string s) { extraction_step_ = std::move(s); }

  std::set<std::string> steps;
  std::set<double> inside_fractions;  // fractions reported during the extraction step
  int updates_after_cancel = 0;

 private:
  mutable std::mutex mutex_;
  std::string current_, extraction_step_;
  bool cancelled_ = false;
};

std::string step_name(Method m) {
  return m == Method::dual_contouring ? "dual contouring" : "marching cubes";
}

TEST(ExtractPart, ProgressMovesInsideOneLargePart) {
  const Image image = ball_image(96);
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    for (double sigma : {0.0, 0.6}) {
      Recorder r;
      r.set_extraction_step(step_name(method));
      MeshingOptions o;
      o.method = method;
      o.volume_sigma_mm = sigma;
      o.smooth.method = SmoothMethod::none;
      const Scene scene = build_scene(image, o, r);
      ASSERT_EQ(scene.parts.size(), 1u);
      EXPECT_TRUE(measure_mesh(scene.parts[0].mesh).closed());
      // Many distinct fractions strictly inside (0, 1): the bar moves during the one part.
      int inside = 0;
      for (double f : r.inside_fractions) inside += f > 0 && f < 1;
      EXPECT_GE(inside, 5) << step_name(method) << " sigma " << sigma;
      EXPECT_NEAR(*r.inside_fractions.rbegin(), 1.0, 1e-9);
    }
  }
}

TEST(ExtractPart, CancelStopsInsideTheExtractionOfOnePart) {
  const Image image = ball_image(160);
  const int threads = tbb::this_task_arena::max_concurrency();
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    Recorder r;
    r.set_extraction_step(step_name(method));
    r.cancel_step = step_name(method);
    r.cancel_at = 0.2;
    MeshingOptions o;
    o.method = method;
    EXPECT_THROW(build_scene(image, o, r), Cancelled) << step_name(method);
    // Only the blocks already running when the cancel came finish (one per thread), and the run
    // never reached the smoothing.
    EXPECT_LE(r.updates_after_cancel, threads) << step_name(method);
    EXPECT_EQ(r.steps.count("smoothing"), 0u) << step_name(method);
    // The cancel came inside the part: its progress had passed 0.2 but not reached the end.
    EXPECT_LT(*r.inside_fractions.rbegin(), 1.0) << step_name(method);
  }
}

TEST(ExtractPart, SmoothingAndComponentsReportInsideOnePart) {
  // The steps around the extraction move too: the components scan by rows, the smoothing of the
  // one part by iterations.
  const Image image = ball_image(96);
  struct Fractions : Progress {
    std::mutex mutex;
    std::string current;
    std::map<std::string, std::set<double>> seen;
    void step(std::string_view name) override {
      std::lock_guard lock(mutex);
      current = name;
    }
    void update(double f) override {
      std::lock_guard lock(mutex);
      seen[current].insert(f);
    }
  } r;
  build_scene(image, {}, r);
  EXPECT_GE(r.seen["components"].size(), 3u);
  EXPECT_GE(r.seen["smoothing"].size(), 10u);  // 20 sinc iterations of one part
}

TEST(ExtractPart, TheDispatchGivesWhatEachExtractorGives) {
  // A label part without volume smoothing comes straight from its runs; with it, from the
  // smoothed mask; a volume smoothing that would erase the part falls back and says so.
  const Image image = ball_image(24);
  const auto& labels = std::get<LabelVolume>(image.volume);
  const Components components = find_components(labels, {});
  ASSERT_EQ(components.components.size(), 1u);
  const PartSource source{image, components, {}};
  MeshingOptions o = resolve_meshing_options({});
  const PartMesh plain = extract_part(source, components.components[0], o);
  EXPECT_FALSE(plain.unsmoothed_fallback);
  EXPECT_TRUE(measure_mesh(plain.mesh).closed());
  o.volume_sigma_mm = 40;  // far wider than the ball: the smoothed field never reaches 0.5
  const PartMesh fallback = extract_part(source, components.components[0], o);
  EXPECT_TRUE(fallback.unsmoothed_fallback);
  EXPECT_EQ(fallback.mesh.triangle_count(), plain.mesh.triangle_count());
}

}  // namespace
}  // namespace segmesh
