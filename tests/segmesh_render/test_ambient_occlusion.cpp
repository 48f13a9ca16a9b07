// Ambient occlusion on the crease scene of issue 40 (crease_scene.hpp): a fragment resting on a
// bone block and a screw entering it, rendered with occlusion on and off from the same camera, as
// `segmesh render` renders (supersample 2) and as the viewer does (supersample 1). Measured on the
// pixels: the object pixels darken visibly at the creases (99th percentile at least 8 of 255), the
// block's flat open top does not (within 2 of 255), and both front ends see the same occlusion.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "segmesh_render/crease_scene.hpp"
#include "segmesh_render/render_test_support.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

using namespace segmesh::render;

constexpr int kW = 512, kH = 384;

struct AoCreases : test::RenderFixture {
  Scene scene = test::crease_scene();
  Camera camera = test::crease_camera(scene, kW, kH);
  // Parts are ordered by label, then by size: the block, the fragment, the screw.
  static constexpr int kBlock = 0, kFragment = 1, kScrew = 2;

  void SetUp() override {
    RenderFixture::SetUp();
    ASSERT_EQ(scene.parts.size(), 3u);
    ASSERT_EQ(scene.parts[kBlock].role, Role::bone);
    ASSERT_EQ(scene.parts[kFragment].role, Role::bone);
    ASSERT_EQ(scene.parts[kScrew].role, Role::implant);
    ASSERT_LT(scene.parts[kFragment].voxels, scene.parts[kBlock].voxels / 20);
  }

  // The on and off pictures at `supersample`, kept in the scratch folder to look at.
  std::pair<RgbaImage, RgbaImage> pair(int supersample) {
    RenderOptions on, off;
    on.supersample = off.supersample = supersample;
    off.ambient_occlusion = false;
    std::pair<RgbaImage, RgbaImage> p{renderer->render_image(scene, camera, on, kW, kH),
                                      renderer->render_image(scene, camera, off, kW, kH)};
    static const auto dir = test::scratch_dir("ao_pictures");
    const std::string tag = "_ss" + std::to_string(supersample) + ".png";
    write_png(p.first, dir / ("creases_ao_on" + tag));
    write_png(p.second, dir / ("creases_ao_off" + tag));
    return p;
  }

  static double mean(const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0 : s / double(v.size());
  }
};

TEST_F(AoCreases, DarkensContactCreasesAndScrewEntriesButNotFlatOpenSurfaces) {
  const std::vector<int32_t> ids = renderer->render_ids(scene, camera, RenderOptions{}, kW, kH);
  const double radius = ao_parameters(RenderOptions{}, scene_bounds(scene).diagonal()).radius_mm;
  const std::vector<int> objects = test::object_pixels(ids);
  // The top farther than the radius (and 1 mm more) from the fragment, the screw and the edges.
  const std::vector<int> open = test::open_top_pixels(ids, camera, kW, kH, kBlock, radius + 1);
  // The top within 2 mm of the fragment's outline and of the screw's shaft.
  const std::vector<int> fragment_crease = test::top_pixels_where(
      ids, camera, kW, kH, kBlock, [](Vec3d p) { return test::outside_fragment(p) < 2; });
  const std::vector<int> screw_entry = test::top_pixels_where(
      ids, camera, kW, kH, kBlock, [](Vec3d p) { return test::outside_shaft(p) < 2; });
  ASSERT_GT(objects.size(), 50000u);
  ASSERT_GT(open.size(), 5000u);
  ASSERT_GT(fragment_crease.size(), 300u);
  ASSERT_GT(screw_entry.size(), 50u);

  std::vector<double> p99, open_p99;
  for (int supersample : {2, 1}) {
    const auto [on, off] = pair(supersample);
    const std::vector<double> all = test::darkening(on, off, objects);
    std::vector<double> flat = test::darkening(on, off, open);
    for (double& d : flat) d = std::abs(d);
    const double fragment = mean(test::darkening(on, off, fragment_crease));
    const double screw = mean(test::darkening(on, off, screw_entry));
    p99.push_back(test::quantile(all, 0.99));
    open_p99.push_back(test::quantile(flat, 0.99));
    std::printf("supersample %d, radius %.2f mm: object pixels (%zu) darker by %.1f of 255 at the 99th "
                "percentile, %.2f on average; fragment crease (%zu) %.1f, screw entry (%zu) %.1f; "
                "flat open top (%zu) %.2f at the 99th percentile, largest %.2f\n",
                supersample, radius, objects.size(), p99.back(), mean(all), fragment_crease.size(),
                fragment, screw_entry.size(), screw, open.size(), open_p99.back(),
                test::quantile(flat, 1.0));
    EXPECT_GE(p99.back(), 8) << "supersample " << supersample;
    EXPECT_LE(open_p99.back(), 2) << "supersample " << supersample;
    EXPECT_GE(fragment, 8) << "supersample " << supersample;
    EXPECT_GE(screw, 8) << "supersample " << supersample;
  }
  // `segmesh render` (supersample 2) and the viewer (1) darken alike: the occlusion is computed
  // per output pixel with radius and bias in millimetres.
  EXPECT_NEAR(p99[0], p99[1], 1.5);
}

TEST_F(AoCreases, RadiusAndBiasAreMillimetresScaledToTheScene) {
  // 6 % of the visible parts' diagonal, clamped to 2..10 mm; bias 3 % of the radius; explicit
  // values win.
  EXPECT_DOUBLE_EQ(ao_parameters({}, 100).radius_mm, 6);
  EXPECT_DOUBLE_EQ(ao_parameters({}, 100).bias_mm, 0.18);
  EXPECT_DOUBLE_EQ(ao_parameters({}, 10).radius_mm, 2);
  EXPECT_DOUBLE_EQ(ao_parameters({}, 0).radius_mm, 2);
  EXPECT_DOUBLE_EQ(ao_parameters({}, 1000).radius_mm, 10);
  RenderOptions o;
  o.ao_radius_mm = 4;
  o.ao_bias_mm = 0.05;
  EXPECT_DOUBLE_EQ(ao_parameters(o, 1000).radius_mm, 4);
  EXPECT_DOUBLE_EQ(ao_parameters(o, 1000).bias_mm, 0.05);
}

TEST_F(AoCreases, LargerRadiusDarkensMoreWhileFlatOpenSurfacesStayOpen) {
  const std::vector<int32_t> ids = renderer->render_ids(scene, camera, RenderOptions{}, kW, kH);
  const std::vector<int> objects = test::object_pixels(ids);
  const std::vector<int> open = test::open_top_pixels(ids, camera, kW, kH, kBlock, 11);
  RenderOptions off;
  off.ambient_occlusion = false;
  const RgbaImage without = renderer->render_image(scene, camera, off, kW, kH);
  double last = -1;
  for (double r : {2.0, 5.0, 10.0}) {
    RenderOptions on;
    on.ao_radius_mm = r;
    const RgbaImage with = renderer->render_image(scene, camera, on, kW, kH);
    const double dark = mean(test::darkening(with, without, objects));
    std::vector<double> flat = test::darkening(with, without, open);
    for (double& d : flat) d = std::abs(d);
    std::printf("radius %.0f mm: object pixels darker by %.2f on average; open top %.2f at most\n", r,
                dark, test::quantile(flat, 1.0));
    EXPECT_GT(dark, last);
    EXPECT_LE(test::quantile(flat, 0.99), 2) << "radius " << r;
    last = dark;
  }
}

}  // namespace
}  // namespace segmesh
