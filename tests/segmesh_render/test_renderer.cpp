// The renderer on the phantom, headless (EGL; Mesa's llvmpipe in CI): materials, visibility,
// ambient occlusion, quality colours, picking, the clipping plane and the standard views, each
// measured on the pixels. Parts are found through the id pass (render_ids), whose agreement with
// the geometry is itself checked against a ray cast on the CPU.
#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <limits>

#include "segmesh_render/render_test_support.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

using namespace segmesh::render;
using test::RenderFixture;

// Portrait, small: the phantom leg is four times as tall as it is wide.
constexpr int kW = 200, kH = 400;

// Writes a picture into the test's scratch folder, to look at when a test fails.
void keep(const RgbaImage& img, const std::string& name) {
  static const auto dir = test::scratch_dir("render_pictures");
  write_png(img, dir / (name + ".png"));
}

struct Renders : RenderFixture {
  Scene scene = test::phantom_scene();
  test::PhantomParts parts = test::phantom_parts(scene);

  void SetUp() override {
    RenderFixture::SetUp();
    ASSERT_EQ(scene.parts.size(), 10u);
    ASSERT_GE(parts.fibula, 0);
    ASSERT_GE(parts.proximal_tibia, 0);
    ASSERT_GE(parts.distal_tibia, 0);
    ASSERT_EQ(parts.screws.size(), 6u);
  }

  Camera view(StandardView v, int w = kW, int h = kH) const {
    return standard_camera(scene, v, double(w) / h);
  }

  bool is_implant(int32_t id) const { return test::contains(parts.implants, id); }
  bool is_bone(int32_t id) const { return test::contains(parts.bones, id); }
};

TEST_F(Renders, ImageHasTheRequestedSizeImplantIsRedAndBoneIsBright) {
  RenderOptions o;
  o.supersample = 2;
  for (auto [w, h] : {std::pair{kW, kH}, std::pair{97, 211}}) {
    const RgbaImage img = renderer->render_image(scene, view(StandardView::anterior, w, h), o, w, h);
    EXPECT_EQ(img.width, w);
    EXPECT_EQ(img.height, h);
    EXPECT_EQ(img.rgba.size(), size_t(w) * h * 4);
  }
  const Camera camera = view(StandardView::iso);
  const RgbaImage img = renderer->render_image(scene, camera, o, kW, kH);
  keep(img, "iso");
  const std::vector<int32_t> ids = renderer->render_ids(scene, camera, o, kW, kH);
  const auto implant = test::interior_pixels(ids, kW, kH, [&](int32_t id) { return is_implant(id); });
  const auto bone = test::interior_pixels(ids, kW, kH, [&](int32_t id) { return is_bone(id); });
  const auto background = test::interior_pixels(ids, kW, kH, [](int32_t id) { return id < 0; });
  ASSERT_GT(implant.size(), 100u);
  ASSERT_GT(bone.size(), 2000u);
  int red = 0;
  double r = 0, g = 0, b = 0;
  for (int p : implant) {
    const uint8_t* px = img.rgba.data() + 4 * p;
    red += test::red_dominant(px);
    r += px[0], g += px[1], b += px[2];
  }
  double bone_luma = 0, background_luma = 0;
  int bright = 0;
  for (int p : bone) {
    const double l = test::luminance(img.rgba.data() + 4 * p);
    bone_luma += l;
    bright += l > 140;
  }
  for (int p : background) background_luma += test::luminance(img.rgba.data() + 4 * p);
  bone_luma /= bone.size();
  background_luma /= background.size();
  std::printf("implant pixels %zu: %.1f %% red-dominant, mean RGB %.0f %.0f %.0f; bone pixels %zu: "
              "mean luminance %.1f, %.1f %% above 140; background %.1f\n",
              implant.size(), 100.0 * red / implant.size(), r / implant.size(), g / implant.size(),
              b / implant.size(), bone.size(), bone_luma, 100.0 * bright / bone.size(), background_luma);
  EXPECT_GT(red, int(0.95 * implant.size()));
  EXPECT_GT(bone_luma, 170);
  EXPECT_GT(bright, int(0.9 * bone.size()));
  EXPECT_LT(background_luma, 100);
  // Bone is near-white: no channel dominates.
  for (int p : bone) {
    const uint8_t* px = img.rgba.data() + 4 * p;
    EXPECT_FALSE(test::red_dominant(px) || test::blue_dominant(px) || test::green_dominant(px));
  }
}

TEST_F(Renders, HidingTheImplantRemovesTheRedPixels) {
  RenderOptions o;
  o.supersample = 2;
  auto red_pixels = [&](const Scene& s) {
    const RgbaImage img = renderer->render_image(s, view(StandardView::iso), o, kW, kH);
    int n = 0;
    for (size_t i = 0; i < img.rgba.size(); i += 4) n += test::red_dominant(&img.rgba[i]);
    return n;
  };
  const int with = red_pixels(scene);
  Scene hidden = scene;
  for (int i : parts.implants) hidden.parts[i].visible = false;
  const int without = red_pixels(hidden);
  std::printf("red-dominant pixels: %d with the implant, %d hidden\n", with, without);
  EXPECT_GT(with, 300);
  EXPECT_EQ(without, 0);
}

// Mean luminance of `pixels` in `img`.
double mean_luminance(const RgbaImage& img, const std::vector<int>& pixels) {
  double sum = 0;
  for (int p : pixels) sum += test::luminance(img.rgba.data() + 4 * p);
  return pixels.empty() ? 0 : sum / pixels.size();
}

TEST_F(Renders, AmbientOcclusionDarkensTheCreaseBetweenPlateAndBone) {
  // Face the plate (anteromedial: azimuth 60) closely enough to resolve its rim.
  Camera camera;
  camera.azimuth_deg = 60;
  camera.elevation_deg = 10;
  Bounds plate = transformed_bounds(mesh_bounds(scene.parts[parts.plate].mesh), identity_transform());
  fit(camera, plate, double(kW) / kH, 1.3);
  RenderOptions on, off;
  off.ambient_occlusion = false;
  const RgbaImage with = renderer->render_image(scene, camera, on, kW, kH);
  const RgbaImage without = renderer->render_image(scene, camera, off, kW, kH);
  keep(with, "crease_ao_on");
  keep(without, "crease_ao_off");
  const std::vector<int32_t> ids = renderer->render_ids(scene, camera, on, kW, kH);
  // Bone pixels within 3 pixels of the plate (the crease), and bone pixels at least 25 pixels
  // from any implant (open bone surface).
  std::vector<int> rim, open;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (!is_bone(ids[size_t(y) * kW + x])) continue;
      int nearest = std::numeric_limits<int>::max();
      for (int dy = -25; dy <= 25; ++dy)
        for (int dx = -25; dx <= 25; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= kW || yy >= kH) continue;
          if (is_implant(ids[size_t(yy) * kW + xx])) nearest = std::min(nearest, std::max(std::abs(dx), std::abs(dy)));
        }
      if (nearest <= 3) rim.push_back(y * kW + x);
      if (nearest == std::numeric_limits<int>::max()) open.push_back(y * kW + x);
    }
  ASSERT_GT(rim.size(), 200u);
  ASSERT_GT(open.size(), 500u);
  const double rim_with = mean_luminance(with, rim), rim_without = mean_luminance(without, rim);
  const double open_with = mean_luminance(with, open), open_without = mean_luminance(without, open);
  std::printf("crease (%zu bone pixels beside the plate): luminance %.1f with ambient occlusion, %.1f "
              "without (%.1f %% darker); open bone (%zu pixels): %.1f with, %.1f without (%.1f %%)\n",
              rim.size(), rim_with, rim_without, 100 * (1 - rim_with / rim_without), open.size(),
              open_with, open_without, 100 * (1 - open_with / open_without));
  EXPECT_LT(rim_with, rim_without - 12);
  // The darkening is about the crease, not a dimmer picture.
  EXPECT_GT(rim_without - rim_with, 3 * (open_without - open_with));
}

TEST_F(Renders, QualityColouringShowsBlueAndGreenOnMarchingCubes) {
  MeshingOptions mc;
  mc.smooth.method = SmoothMethod::none;
  const Scene raw = test::phantom_scene(mc);
  for (const Part& p : raw.parts) ASSERT_TRUE(p.mesh.colors.empty());  // computed by the renderer
  // Marching Cubes triangles on 4 mm slices: needles on the sides (blue), good triangles on the
  // axial caps (green); the iso view sees both.
  const Camera camera = standard_camera(raw, StandardView::iso, double(kW) / kH);
  auto count = [&](ColorMode mode) {
    RenderOptions o;
    o.color = mode;
    const RgbaImage img = renderer->render_image(raw, camera, o, kW, kH);
    keep(img, std::string("colors_") + std::string(color_mode_name(mode)));
    std::pair<int, int> bg{0, 0};
    for (size_t i = 0; i < img.rgba.size(); i += 4) {
      bg.first += test::blue_dominant(&img.rgba[i]);
      bg.second += test::green_dominant(&img.rgba[i]);
    }
    return bg;
  };
  const auto quality = count(ColorMode::quality);
  const auto material = count(ColorMode::material);
  std::printf("quality colours: %d blue-dominant and %d green-dominant pixels (material: %d, %d)\n",
              quality.first, quality.second, material.first, material.second);
  EXPECT_GT(quality.first, 200);
  EXPECT_GT(quality.second, 200);
  EXPECT_EQ(material.first + material.second, 0);
}

// The part a ray through each pixel centre hits first, computed on the CPU from the triangles
// (Moeller-Trumbore), -1 for none: the reference the GPU's id pass is checked against. Each
// triangle is tested only against the pixels inside its projected bounding box.
std::vector<int32_t> ray_cast_ids(const Scene& scene, const Camera& camera, int w, int h) {
  std::vector<int32_t> ids(size_t(w) * h, -1);
  std::vector<double> nearest(ids.size(), std::numeric_limits<double>::infinity());
  std::vector<Ray> rays(ids.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) rays[size_t(y) * w + x] = pixel_ray(camera, w, h, x + 0.5, y + 0.5);
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    const Part& part = scene.parts[i];
    if (!part.visible) continue;
    std::vector<std::optional<Vec3d>> screen(part.mesh.positions.size());
    for (size_t v = 0; v < screen.size(); ++v) {
      screen[v] = project_to_pixel(camera, w, h, to_double(part.mesh.positions[v]));
    }
    const auto& idx = part.mesh.indices;
    for (size_t t = 0; t < idx.size(); t += 3) {
      const auto& s0 = screen[idx[t]];
      const auto& s1 = screen[idx[t + 1]];
      const auto& s2 = screen[idx[t + 2]];
      if (!s0 || !s1 || !s2) continue;
      const int x0 = std::max(0, int(std::floor(std::min({s0->x, s1->x, s2->x}) - 0.5)));
      const int x1 = std::min(w - 1, int(std::ceil(std::max({s0->x, s1->x, s2->x}))));
      const int y0 = std::max(0, int(std::floor(std::min({s0->y, s1->y, s2->y}) - 0.5)));
      const int y1 = std::min(h - 1, int(std::ceil(std::max({s0->y, s1->y, s2->y}))));
      const Vec3d a = to_double(part.mesh.positions[idx[t]]);
      const Vec3d e1 = to_double(part.mesh.positions[idx[t + 1]]) - a;
      const Vec3d e2 = to_double(part.mesh.positions[idx[t + 2]]) - a;
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const size_t pixel = size_t(y) * w + x;
          const Ray& ray = rays[pixel];
          const Vec3d p = cross(ray.direction, e2);
          const double det = dot(e1, p);
          if (std::abs(det) < 1e-14) continue;
          const Vec3d sv = ray.origin - a;
          const double u = dot(sv, p) / det;
          if (u < 0 || u > 1) continue;
          const Vec3d q = cross(sv, e1);
          const double v = dot(ray.direction, q) / det;
          if (v < 0 || u + v > 1) continue;
          const double dist = dot(e2, q) / det;
          if (dist > 0 && dist < nearest[pixel]) {
            nearest[pixel] = dist;
            ids[pixel] = int32_t(i);
          }
        }
    }
  }
  return ids;
}

TEST_F(Renders, PickFindsThePartAGeometricRayCastFinds) {
  const RenderOptions o;
  for (StandardView v : {StandardView::iso, StandardView::left}) {
    const Camera camera = view(v);
    const std::vector<int32_t> expected = ray_cast_ids(scene, camera, kW, kH);
    const std::vector<int32_t> ids = renderer->render_ids(scene, camera, o, kW, kH);
    int agree = 0, on_parts = 0;
    std::vector<int> seen(scene.parts.size(), 0);
    for (size_t p = 0; p < ids.size(); ++p) {
      agree += ids[p] == expected[p];
      if (expected[p] >= 0) {
        ++on_parts;
        ++seen[expected[p]];
      }
    }
    std::printf("%s view: the id pass agrees with the ray cast at %d of %zu pixels (%d on parts)\n",
                std::string(view_name(v)).c_str(), agree, ids.size(), on_parts);
    EXPECT_GT(on_parts, 4000);
    // Pixels whose centre lies within rounding of a silhouette or a triangle edge may differ.
    EXPECT_GT(agree, int(ids.size()) - int(ids.size()) / 200);
    // pick() renders the same pass for one pixel: 40 pixels on parts and 10 of the background.
    std::vector<size_t> on, off;
    for (size_t p = 0; p < ids.size(); ++p) (ids[p] >= 0 ? on : off).push_back(p);
    std::vector<size_t> probes;
    for (size_t k = 0; k < 40; ++k) probes.push_back(on[k * on.size() / 40]);
    for (size_t k = 0; k < 10; ++k) probes.push_back(off[k * off.size() / 10]);
    int checked = 0, picked_right = 0;
    for (size_t p : probes) {
      const auto got = renderer->pick(scene, camera, o, kW, kH, int(p % kW), int(p / kW));
      picked_right += (got ? int32_t(*got) : -1) == ids[p];
      ++checked;
    }
    EXPECT_EQ(picked_right, checked);
    EXPECT_GT(seen[parts.proximal_tibia], 100);
    EXPECT_GT(seen[parts.plate], 50);
  }
  // The plate's centre, straight on.
  Camera front;
  front.azimuth_deg = 60;
  fit(front, mesh_bounds(scene.parts[parts.plate].mesh), double(kW) / kH, 1.5);
  const RenderOptions o2;
  EXPECT_EQ(renderer->pick(scene, front, o2, kW, kH, kW / 2, kH / 2), std::optional<size_t>(parts.plate));
  const Camera camera = view(StandardView::iso);
  EXPECT_EQ(renderer->pick(scene, camera, o2, kW, kH, 0, 0), std::nullopt);   // background
  EXPECT_EQ(renderer->pick(scene, camera, o2, kW, kH, kW, 0), std::nullopt);  // outside the view
  // Hidden parts are not picked: what lies behind the plate is.
  Scene hidden = scene;
  hidden.parts[parts.plate].visible = false;
  const auto behind = renderer->pick(hidden, front, o2, kW, kH, kW / 2, kH / 2);
  ASSERT_TRUE(behind.has_value());
  EXPECT_NE(*behind, size_t(parts.plate));
}

TEST_F(Renders, ClippingPlaneRevealsTheScrewsInsideTheBone) {
  // Anterior view; the plane through the tibia's axis keeps its posterior half (normal +y), so
  // the anterior cortex, the plate and the screw heads are cut away.
  const Camera camera = view(StandardView::anterior);
  RenderOptions plain, cut;
  cut.clip = ClipPlane{{12, -8, 0}, {0, 1, 0}};
  const std::vector<int32_t> before = renderer->render_ids(scene, camera, plain, kW, kH);
  const std::vector<int32_t> after = renderer->render_ids(scene, camera, cut, kW, kH);
  const RgbaImage img_before = renderer->render_image(scene, camera, plain, kW, kH);
  const RgbaImage img_after = renderer->render_image(scene, camera, cut, kW, kH);
  keep(img_after, "clipped");
  int bone_before = 0, red_before = 0, red_after = 0, screws_after = 0;
  for (int p = 0; p < kW * kH; ++p) {
    if (!is_bone(before[p])) continue;  // where bone was in front
    ++bone_before;
    red_before += test::red_dominant(&img_before.rgba[4 * p]);
    red_after += test::red_dominant(&img_after.rgba[4 * p]);
    screws_after += test::contains(parts.screws, after[p]);
  }
  std::printf("of %d pixels where bone was in front: %d red before the cut, %d red after it (%d "
              "screw pixels by id)\n", bone_before, red_before, red_after, screws_after);
  EXPECT_EQ(red_before, 0);
  EXPECT_GT(red_after, 60);
  EXPECT_GT(screws_after, 60);
  // The cut surface is drawn (the bone does not vanish where it is cut) and differs from the
  // bone's outer surface: hatched and darker.
  const auto section = test::interior_pixels(after, kW, kH, [&](int32_t id) {
    return id == parts.proximal_tibia || id == parts.distal_tibia;
  });
  int darker = 0, kept = 0;
  for (int p : section) {
    if (!is_bone(before[p])) continue;
    ++kept;
    darker += test::luminance(&img_after.rgba[4 * p]) < test::luminance(&img_before.rgba[4 * p]) - 30;
  }
  EXPECT_GT(kept, 1000);
  EXPECT_GT(darker, kept / 2);
}

// Pixel count and mean position of each part in an id image.
struct Footprint {
  int pixels = 0;
  double x = 0, y = 0;
};
Footprint footprint(const std::vector<int32_t>& ids, int w, const std::vector<int>& which) {
  Footprint f;
  for (size_t p = 0; p < ids.size(); ++p) {
    if (!test::contains(which, ids[p])) continue;
    ++f.pixels;
    f.x += double(p % w);
    f.y += double(p / w);
  }
  if (f.pixels) f.x /= f.pixels, f.y /= f.pixels;
  return f;
}

TEST_F(Renders, StandardViewsShowTheAnatomyFromTheirSide) {
  const RenderOptions o;
  auto ids = [&](StandardView v) { return renderer->render_ids(scene, view(v), o, kW, kH); };
  const std::vector<int> plate{parts.plate}, fibula{parts.fibula};
  const std::vector<int> tibia{parts.proximal_tibia, parts.distal_tibia};
  const auto anterior = ids(StandardView::anterior), posterior = ids(StandardView::posterior);
  // The plate is anteromedial: in front of the tibia in the anterior view (nearly all of its
  // silhouette is seen), behind it in the posterior view (most of it is hidden).
  Scene plate_only = scene;
  for (size_t i = 0; i < plate_only.parts.size(); ++i) plate_only.parts[i].visible = int(i) == parts.plate;
  auto seen_fraction = [&](StandardView v, const std::vector<int32_t>& all) {
    const auto alone = renderer->render_ids(plate_only, view(v), o, kW, kH);
    return double(footprint(all, kW, plate).pixels) / std::max(1, footprint(alone, kW, plate).pixels);
  };
  const double front = seen_fraction(StandardView::anterior, anterior);
  const double back = seen_fraction(StandardView::posterior, posterior);
  std::printf("share of the plate's silhouette seen: %.2f anterior, %.2f posterior\n", front, back);
  EXPECT_GT(front, 0.85);
  EXPECT_LT(back, 0.5);
  // Superior up; the patient's left (+x, the tibia's side of the fibula) on the right in the
  // anterior view and on the left in the posterior one.
  const Footprint proximal = footprint(anterior, kW, {parts.proximal_tibia});
  const Footprint distal = footprint(anterior, kW, {parts.distal_tibia});
  EXPECT_LT(proximal.y, distal.y);
  EXPECT_LT(footprint(anterior, kW, fibula).x, footprint(anterior, kW, tibia).x);
  EXPECT_GT(footprint(posterior, kW, fibula).x, footprint(posterior, kW, tibia).x);
  // Left view (eye at +x): the tibia hides much of the fibula; posterior (the fibula) on the right.
  const auto left = ids(StandardView::left), right = ids(StandardView::right);
  EXPECT_GT(footprint(left, kW, fibula).x, footprint(left, kW, tibia).x);
  EXPECT_LT(footprint(right, kW, fibula).x, footprint(right, kW, tibia).x);
  EXPECT_GT(footprint(left, kW, plate).pixels, 3 * footprint(right, kW, plate).pixels);
  // Superior and inferior: anterior up (the tibia, anterior to the fibula, is higher on the
  // screen); the patient's right (the fibula) on the right from above, on the left from below.
  const auto superior = ids(StandardView::superior), inferior = ids(StandardView::inferior);
  EXPECT_LT(footprint(superior, kW, tibia).y, footprint(superior, kW, fibula).y);
  EXPECT_LT(footprint(inferior, kW, tibia).y, footprint(inferior, kW, fibula).y);
  EXPECT_GT(footprint(superior, kW, fibula).x, footprint(superior, kW, tibia).x);
  EXPECT_LT(footprint(inferior, kW, fibula).x, footprint(inferior, kW, tibia).x);
  // Fit to scene: every view shows the whole visible scene, with little margin.
  for (StandardView v : {StandardView::anterior, StandardView::left, StandardView::superior,
                         StandardView::iso}) {
    const auto image = ids(v);
    int minx = kW, maxx = -1, miny = kH, maxy = -1;
    for (int p = 0; p < kW * kH; ++p) {
      if (image[p] < 0) continue;
      minx = std::min(minx, p % kW), maxx = std::max(maxx, p % kW);
      miny = std::min(miny, p / kW), maxy = std::max(maxy, p / kW);
    }
    EXPECT_GT(minx, 0) << view_name(v);
    EXPECT_GT(miny, 0) << view_name(v);
    EXPECT_LT(maxx, kW - 1) << view_name(v);
    EXPECT_LT(maxy, kH - 1) << view_name(v);
    // The scene fills the viewport along one axis at least to 70 %.
    EXPECT_TRUE(maxx - minx > 0.7 * kW || maxy - miny > 0.7 * kH) << view_name(v);
  }
}

TEST_F(Renders, TransformsOpacityAndSelectionChangeWhatIsDrawn) {
  const Camera camera = view(StandardView::anterior);
  const RenderOptions o;
  const std::vector<int> plate{parts.plate};
  const Footprint at_rest = footprint(renderer->render_ids(scene, camera, o, kW, kH), kW, plate);
  // Move the plate 30 mm to the patient's left (+x): right on the screen in the anterior view.
  Scene moved = scene;
  moved.parts[parts.plate].transform[12] = 30;
  const Footprint shifted = footprint(renderer->render_ids(moved, camera, o, kW, kH), kW, plate);
  EXPECT_GT(shifted.x, at_rest.x + 5);
  EXPECT_NEAR(shifted.y, at_rest.y, 2);

  // Translucent bone shows the screws inside it: where a screw lies behind bone, the colour turns
  // towards red.
  RenderOptions glass;
  glass.opacity.assign(scene.parts.size(), 1.0f);
  for (int b : parts.bones) glass.opacity[b] = 0.3f;
  Scene screws_only = scene;
  for (size_t i = 0; i < screws_only.parts.size(); ++i) {
    screws_only.parts[i].visible = test::contains(parts.screws, int32_t(i));
  }
  const auto all_ids = renderer->render_ids(scene, camera, o, kW, kH);
  const auto screw_ids = renderer->render_ids(screws_only, camera, o, kW, kH);
  const RgbaImage solid = renderer->render_image(scene, camera, o, kW, kH);
  const RgbaImage see_through = renderer->render_image(scene, camera, glass, kW, kH);
  keep(see_through, "translucent_bone");
  double redness_solid = 0, redness_glass = 0;
  int behind = 0;
  for (int p = 0; p < kW * kH; ++p) {
    if (!is_bone(all_ids[p]) || screw_ids[p] < 0) continue;
    ++behind;
    auto redness = [](const uint8_t* px) { return px[0] - 0.5 * (px[1] + px[2]); };
    redness_solid += redness(&solid.rgba[4 * p]);
    redness_glass += redness(&see_through.rgba[4 * p]);
  }
  ASSERT_GT(behind, 50);
  std::printf("screws behind bone (%d pixels): redness %.1f through opaque bone, %.1f through bone "
              "at opacity 0.3\n", behind, redness_solid / behind, redness_glass / behind);
  EXPECT_GT(redness_glass / behind, redness_solid / behind + 40);

  // The selected part gets a highlight; nothing else changes.
  RenderOptions selected;
  selected.selected = parts.plate;
  const RgbaImage a = renderer->render_image(scene, camera, o, kW, kH);
  const RgbaImage b = renderer->render_image(scene, camera, selected, kW, kH);
  const std::vector<int32_t> ids = renderer->render_ids(scene, camera, o, kW, kH);
  int changed_plate = 0, changed_other = 0;
  for (int p = 0; p < kW * kH; ++p) {
    const bool differs = std::memcmp(&a.rgba[4 * p], &b.rgba[4 * p], 3) != 0;
    (ids[p] == parts.plate ? changed_plate : changed_other) += differs;
  }
  EXPECT_GT(changed_plate, 50);
  EXPECT_LT(changed_other, 20);  // anti-aliased edges of the plate only
}

TEST_F(Renders, MeshChangesAreUploadedAgain) {
  const Camera camera = view(StandardView::anterior);
  const RenderOptions o;
  renderer->sync(scene);
  EXPECT_EQ(renderer->last_frame().meshes_uploaded, 10);
  const RgbaImage first = renderer->render_image(scene, camera, o, kW, kH);
  EXPECT_EQ(renderer->last_frame().meshes_uploaded, 0);
  EXPECT_EQ(renderer->last_frame().parts_drawn, 10);
  // A copy of the scene is the same meshes: nothing is uploaded.
  const Scene copy = scene;
  renderer->render_image(copy, camera, o, kW, kH);
  EXPECT_EQ(renderer->last_frame().meshes_uploaded, 0);
  // Every vertex of the fibula moved 20 mm up: found and uploaded again.
  Scene edited = scene;
  for (Vec3f& p : edited.parts[parts.fibula].mesh.positions) p.z += 20;
  const std::vector<int> fibula{parts.fibula};
  const Footprint before = footprint(renderer->render_ids(scene, camera, o, kW, kH), kW, fibula);
  const Footprint after = footprint(renderer->render_ids(edited, camera, o, kW, kH), kW, fibula);
  EXPECT_LT(after.y, before.y - 3);
  // A part removed and the rest drawn.
  Scene fewer = scene;
  fewer.parts.resize(3);
  renderer->render_image(fewer, camera, o, kW, kH);
  EXPECT_EQ(renderer->last_frame().parts_drawn, 3);
  renderer->invalidate(1);
  renderer->sync(fewer);
  EXPECT_EQ(renderer->last_frame().meshes_uploaded, 1);
}

TEST_F(Renders, DrawsIntoTheCallersFramebufferAndViewportAndRestoresThem) {
  // The viewer's path: its own framebuffer (here an offscreen one) and a viewport inside it.
  GLuint fbo = 0, color = 0;
  glGenRenderbuffers(1, &color);
  glBindRenderbuffer(GL_RENDERBUFFER, color);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, 200, 150);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
  ASSERT_EQ(glCheckFramebufferStatus(GL_FRAMEBUFFER), GLenum(GL_FRAMEBUFFER_COMPLETE));
  glViewport(0, 0, 200, 150);
  glClearColor(1, 0, 1, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  const Viewport vp{50, 30, 120, 100};
  renderer->draw(scene, standard_camera(scene, StandardView::anterior, 1.2), RenderOptions{}, vp);
  GLint bound = 0, viewport[4];
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
  glGetIntegerv(GL_VIEWPORT, viewport);
  EXPECT_EQ(GLuint(bound), fbo);
  EXPECT_EQ(viewport[2], 200);
  EXPECT_EQ(viewport[3], 150);
  // read_framebuffer (a screenshot of whatever is bound) returns the rows top first.
  const RgbaImage shot = read_framebuffer(Viewport{0, 0, 200, 150});
  ASSERT_EQ(shot.rgba.size(), 200u * 150 * 4);
  int magenta_inside = 0, magenta_outside = 0, outside = 0;
  for (int y = 0; y < 150; ++y)
    for (int x = 0; x < 200; ++x) {
      const uint8_t* p = shot.pixel(x, 149 - y);  // y counted from the bottom, as OpenGL does
      const bool magenta = p[0] == 255 && p[1] == 0 && p[2] == 255;
      const bool in = x >= vp.x && x < vp.x + vp.width && y >= vp.y && y < vp.y + vp.height;
      (in ? magenta_inside : magenta_outside) += magenta;
      outside += !in;
    }
  // The picture inside the viewport is the one render_image makes at that size.
  const RgbaImage alone = renderer->render_image(
      scene, standard_camera(scene, StandardView::anterior, 1.2), RenderOptions{}, vp.width, vp.height);
  int same = 0;
  for (int y = 0; y < vp.height; ++y)
    for (int x = 0; x < vp.width; ++x) {
      same += std::memcmp(shot.pixel(vp.x + x, 150 - vp.y - vp.height + y), alone.pixel(x, y), 4) == 0;
    }
  EXPECT_EQ(same, vp.width * vp.height);
  EXPECT_EQ(magenta_inside, 0);
  EXPECT_EQ(magenta_outside, outside);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteFramebuffers(1, &fbo);
  glDeleteRenderbuffers(1, &color);
}

}  // namespace
}  // namespace segmesh
