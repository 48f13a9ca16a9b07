// The camera as plain data: standard views in the LPS frame as documented, fit to bounds, orbit,
// pan and zoom, and the pixel ray / projection pair. No OpenGL.
#include <gtest/gtest.h>

#include <cmath>

#include "segmesh_render/camera.hpp"

namespace segmesh {
namespace {

using namespace segmesh::render;

void expect_vec(Vec3d got, Vec3d want, const char* what) {
  EXPECT_NEAR(got.x, want.x, 1e-9) << what;
  EXPECT_NEAR(got.y, want.y, 1e-9) << what;
  EXPECT_NEAR(got.z, want.z, 1e-9) << what;
}

TEST(Camera, StandardViewsLookFromTheirSideWithTheDocumentedUp) {
  struct Expect {
    StandardView view;
    Vec3d forward, up, right;
  };
  // LPS: +x patient's left, +y posterior, +z superior.
  const Expect table[] = {
      {StandardView::anterior, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}},
      {StandardView::posterior, {0, -1, 0}, {0, 0, 1}, {-1, 0, 0}},
      {StandardView::left, {-1, 0, 0}, {0, 0, 1}, {0, 1, 0}},
      {StandardView::right, {1, 0, 0}, {0, 0, 1}, {0, -1, 0}},
      {StandardView::superior, {0, 0, -1}, {0, -1, 0}, {-1, 0, 0}},
      {StandardView::inferior, {0, 0, 1}, {0, -1, 0}, {1, 0, 0}},
  };
  for (const Expect& e : table) {
    Camera c;
    c.target = {10, 20, 30};
    c.distance = 100;
    set_view(c, e.view);
    const CameraFrame f = camera_frame(c);
    const std::string name(view_name(e.view));
    expect_vec(f.forward, e.forward, name.c_str());
    expect_vec(f.up, e.up, name.c_str());
    expect_vec(f.right, e.right, name.c_str());
    expect_vec(f.eye, c.target - 100.0 * e.forward, name.c_str());
    EXPECT_EQ(parse_view(name), e.view);
  }
  Camera iso;
  set_view(iso, StandardView::iso);
  const CameraFrame f = camera_frame(iso);
  EXPECT_GT(f.forward.x, 0.1 - 1);  // looks from anterior, left and above
  EXPECT_LT(f.forward.x, 0);
  EXPECT_GT(f.forward.y, 0);
  EXPECT_LT(f.forward.z, 0);
  EXPECT_FALSE(parse_view("front").has_value());
}

TEST(Camera, FitShowsTheWholeBoxTightly) {
  Bounds box;
  box.add({-50, -50, -200});
  box.add({50, 50, 200});
  {
    for (StandardView v : {StandardView::anterior, StandardView::left, StandardView::superior,
                           StandardView::iso}) {
      for (auto [w, h] : {std::pair{320, 240}, std::pair{240, 480}}) {
        Camera c;
        set_view(c, v);
        fit(c, box, double(w) / h);
        double minx = 1e9, maxx = -1e9, miny = 1e9, maxy = -1e9;
        for (int i = 0; i < 8; ++i) {
          const Vec3d p{i & 1 ? 50.0 : -50.0, i & 2 ? 50.0 : -50.0, i & 4 ? 200.0 : -200.0};
          const auto px = project_to_pixel(c, w, h, p);
          ASSERT_TRUE(px.has_value());
          minx = std::min(minx, px->x), maxx = std::max(maxx, px->x);
          miny = std::min(miny, px->y), maxy = std::max(maxy, px->y);
        }
        const std::string what = std::string(view_name(v)) + " " + std::to_string(w);
        EXPECT_GE(minx, -1e-6) << what;
        EXPECT_GE(miny, -1e-6) << what;
        EXPECT_LE(maxx, w + 1e-6) << what;
        EXPECT_LE(maxy, h + 1e-6) << what;
        // Tight: the box spans at least 85 % of the width or of the height.
        EXPECT_TRUE(maxx - minx > 0.85 * w || maxy - miny > 0.85 * h) << what;
        const ClipRange r = clip_range(c, box);
        EXPECT_LT(r.near, r.far);
        EXPECT_GT(r.near, 0);
      }
    }
  }
}

TEST(Camera, PixelRayAndProjectionAgree) {
  Camera c;
  c.target = {5, -7, 12};
  c.distance = 250;
  c.azimuth_deg = 33;
  c.elevation_deg = -21;
  {
    for (auto [x, y] : {std::pair{0.5, 0.5}, std::pair{160.0, 120.0}, std::pair{300.25, 17.75}}) {
      const Ray ray = pixel_ray(c, 320, 240, x, y);
      EXPECT_NEAR(norm(ray.direction), 1, 1e-12);
      const auto px = project_to_pixel(c, 320, 240, ray.origin + 180.0 * ray.direction);
      ASSERT_TRUE(px.has_value());
      EXPECT_NEAR(px->x, x, 1e-6);
      EXPECT_NEAR(px->y, y, 1e-6);
    }
    // The target is at the centre of the view.
    const auto centre = project_to_pixel(c, 320, 240, c.target);
    EXPECT_NEAR(centre->x, 160, 1e-9);
    EXPECT_NEAR(centre->y, 120, 1e-9);
  }
  EXPECT_FALSE(project_to_pixel(c, 320, 240, camera_frame(c).eye - camera_frame(c).forward).has_value());
}

TEST(Camera, OrbitPanAndZoom) {
  Camera c;
  c.distance = 200;
  orbit(c, 30, 100);
  EXPECT_DOUBLE_EQ(c.azimuth_deg, 30);
  EXPECT_DOUBLE_EQ(c.elevation_deg, 90);  // clamped at the pole
  orbit(c, 340, -200);
  EXPECT_NEAR(c.azimuth_deg, 10, 1e-9);    // wrapped
  EXPECT_DOUBLE_EQ(c.elevation_deg, -90);
  c.elevation_deg = 0;
  zoom(c, 2);
  EXPECT_DOUBLE_EQ(c.distance, 100);
  zoom(c, 0);  // ignored
  EXPECT_DOUBLE_EQ(c.distance, 100);
  // Panning by (dx, dy) pixels moves a point at the target's depth by the same pixels on screen.
  const Vec3d p = c.target;
  const auto before = project_to_pixel(c, 400, 300, p);
  pan(c, 40, -25, 300);
  const auto after = project_to_pixel(c, 400, 300, p);
  EXPECT_NEAR(after->x - before->x, 40, 1e-6);
  EXPECT_NEAR(after->y - before->y, -25, 1e-6);
}

TEST(Camera, SceneBoundsFollowVisibilityAndTransforms) {
  Scene scene;
  for (int i = 0; i < 2; ++i) {
    Part p;
    p.mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}};
    p.mesh.indices = {0, 1, 2};
    scene.parts.push_back(p);
  }
  scene.parts[1].transform[12] = 10;  // moved 10 mm along x
  Bounds b = scene_bounds(scene);
  EXPECT_DOUBLE_EQ(b.max.x, 11);
  scene.parts[1].visible = false;
  b = scene_bounds(scene);
  EXPECT_DOUBLE_EQ(b.max.x, 1);
  EXPECT_DOUBLE_EQ(scene_bounds(scene, true).max.x, 11);
  scene.parts[0].visible = false;
  EXPECT_TRUE(scene_bounds(scene).empty());
  // Fitting to nothing leaves the camera alone.
  Camera c;
  const Camera before = c;
  fit(c, scene_bounds(scene), 1.5);
  EXPECT_EQ(c.distance, before.distance);
}

}  // namespace
}  // namespace segmesh
