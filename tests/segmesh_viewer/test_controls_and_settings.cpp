#include <gtest/gtest.h>

#include <fstream>

#include "segmesh/error.hpp"
#include "segmesh_viewer/clip_settings.hpp"
#include "segmesh_viewer/file_browser.hpp"
#include "segmesh_viewer/meshing_settings.hpp"
#include "segmesh_viewer/view_controls.hpp"
#include "support/test_support.hpp"
#include "viewer_test_support.hpp"

namespace segmesh::viewer {
namespace {

namespace fs = std::filesystem;

TEST(ViewControls, ArrowKeysOrbitAndPlusMinusZoom) {
  render::Camera c;
  c.distance = 200;
  apply_view_key(c, ViewKey::left);
  EXPECT_DOUBLE_EQ(c.azimuth_deg, kKeyOrbitStepDeg);
  apply_view_key(c, ViewKey::right);
  apply_view_key(c, ViewKey::right);
  EXPECT_DOUBLE_EQ(c.azimuth_deg, -kKeyOrbitStepDeg);
  apply_view_key(c, ViewKey::up);
  EXPECT_DOUBLE_EQ(c.elevation_deg, kKeyOrbitStepDeg);
  apply_view_key(c, ViewKey::down);
  apply_view_key(c, ViewKey::down);
  EXPECT_DOUBLE_EQ(c.elevation_deg, -kKeyOrbitStepDeg);
  apply_view_key(c, ViewKey::zoom_in);
  EXPECT_NEAR(c.distance, 200 / kKeyZoomFactor, 1e-9);
  apply_view_key(c, ViewKey::zoom_out);
  EXPECT_NEAR(c.distance, 200, 1e-9);
  // A drag to the left turns the scene as the left arrow does.
  render::Camera d;
  drag_orbit(d, -kKeyOrbitStepDeg / kDragOrbitDegPerPixel, 0);
  EXPECT_NEAR(d.azimuth_deg, kKeyOrbitStepDeg, 1e-9);
  wheel_zoom(d, 2);
  EXPECT_NEAR(d.distance, 500 / (kWheelZoomFactor * kWheelZoomFactor), 1e-9);
}

// Every corner of the visible parts' bounds lands inside the viewport.
void expect_framed(const render::Camera& c, const Scene& scene, int w, int h) {
  const render::Bounds b = render::scene_bounds(scene);
  for (int k = 0; k < 8; ++k) {
    const Vec3d corner{k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y, k & 4 ? b.max.z : b.min.z};
    const std::optional<Vec3d> p = render::project_to_pixel(c, w, h, corner);
    ASSERT_TRUE(p.has_value());
    EXPECT_GE(p->x, 0);
    EXPECT_LE(p->x, w);
    EXPECT_GE(p->y, 0);
    EXPECT_LE(p->y, h);
  }
}

TEST(ViewControls, FitAndStandardViewsFrameTheVisibleParts) {
  Scene scene = test::three_boxes();
  render::Camera c;
  c.target = {500, 500, 500};
  c.distance = 5;
  fit_scene(c, scene, 4.0 / 3);
  expect_framed(c, scene, 800, 600);
  for (render::StandardView v : {render::StandardView::anterior, render::StandardView::superior,
                                 render::StandardView::left}) {
    show_standard_view(c, scene, v, 4.0 / 3);
    render::Camera expected;
    render::set_view(expected, v);
    EXPECT_DOUBLE_EQ(c.azimuth_deg, expected.azimuth_deg);
    EXPECT_DOUBLE_EQ(c.elevation_deg, expected.elevation_deg);
    expect_framed(c, scene, 800, 600);
  }
  // Only the small box visible: fit closes in on it.
  const double all_distance = c.distance;
  scene.parts[0].visible = false;
  scene.parts[2].visible = false;
  fit_scene(c, scene, 4.0 / 3);
  EXPECT_LT(c.distance, all_distance);
  EXPECT_NEAR(c.target.x, 23, 1e-9);
  // Nothing visible: everything is framed.
  scene.parts[1].visible = false;
  fit_scene(c, scene, 4.0 / 3);
  EXPECT_NEAR(c.target.z, 20, 1e-9);
}

TEST(MeshingSettings, DefaultsAreThePipelines) {
  const MeshingOptions o = meshing_options(MeshingSettings{});
  const MeshingOptions d;
  EXPECT_EQ(o.method, d.method);
  EXPECT_EQ(o.normals, d.normals);
  EXPECT_EQ(o.smooth.method, d.smooth.method);
  EXPECT_EQ(default_smooth_iterations(o.smooth.method), o.smooth.iterations);
  EXPECT_EQ(o.smooth.preserve_volume, d.smooth.preserve_volume);
  EXPECT_TRUE(o.labels.empty());
}

TEST(MeshingSettings, PanelFieldsBecomeOptions) {
  MeshingSettings s;
  s.method = Method::dual_contouring;
  s.normals = NormalMethod::sobel;
  s.smooth = SmoothMethod::hc;
  s.iterations = 2;
  s.labels = "2,1,7";  // as `--labels` takes them
  s.surfaces = Surfaces::independent;
  s.decimate_error_mm = 0.2;
  s.max_triangles = 5000;
  const MeshingOptions o = meshing_options(s);
  EXPECT_EQ(o.method, Method::dual_contouring);
  EXPECT_EQ(o.normals, NormalMethod::sobel);
  EXPECT_EQ(o.smooth.method, SmoothMethod::hc);
  EXPECT_EQ(o.smooth.iterations, 2);
  EXPECT_EQ(o.labels, (std::vector<int32_t>{2, 1, 7}));
  EXPECT_EQ(o.surfaces, Surfaces::independent);
  EXPECT_EQ(o.decimate.error_mm, 0.2);
  EXPECT_EQ(o.decimate.max_triangles, 5000);
  EXPECT_FALSE(MeshingSettings{}.decimate_error_mm > 0 || MeshingSettings{}.max_triangles > 0);
}

TEST(MeshingSettings, SurfacesAreAutomaticUntilResolved) {
  MeshingSettings s;
  EXPECT_EQ(s.surfaces, Surfaces::automatic);
  // The request keeps "automatic" (so surfaces_note can say why), the resolved options do not.
  EXPECT_EQ(meshing_request(s).surfaces, Surfaces::automatic);
  EXPECT_EQ(meshing_options(s).surfaces, Surfaces::conforming);
  s.method = Method::dual_contouring;  // either method
  EXPECT_EQ(meshing_options(s).surfaces, Surfaces::conforming);
  s.surfaces = Surfaces::conforming;
  EXPECT_EQ(meshing_request(s).surfaces, Surfaces::conforming);
}

TEST(MeshingSettings, LabelsAreReadAsTheCommandLineReadsThem) {
  // The field goes through `--labels`'s own parser: the same text, the same messages.
  auto labels = [](std::string text) {
    MeshingSettings s;
    s.labels = std::move(text);
    return meshing_request(s).labels;
  };
  EXPECT_EQ(labels("-3"), (std::vector<int32_t>{-3}));
  EXPECT_EQ(labels("4,,5,"), (std::vector<int32_t>{4, 5}));
  EXPECT_TRUE(labels("").empty());
  MeshingOptions cli;
  find_meshing_option("labels")->set(cli, "3,1");
  EXPECT_EQ(labels("3,1"), cli.labels);
  for (const char* bad : {"1,x", "1.5", "99999999999", "1 2"}) {
    try {
      labels(bad);
      ADD_FAILURE() << bad << " was taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--labels"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(labels("0"), Error);  // the background: refused when resolving
  MeshingSettings s;
  s.iterations = -1;
  EXPECT_THROW(meshing_options(s), Error);
  // Decimation fields out of range: the command line's messages.
  MeshingSettings d;
  d.decimate_error_mm = -0.5;
  EXPECT_THROW(meshing_request(d), Error);
  d.decimate_error_mm = 0;
  d.max_triangles = -5;
  try {
    meshing_request(d);
    ADD_FAILURE() << "a negative budget was taken";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--max-triangles"), std::string::npos) << e.what();
  }
}

TEST(ClipSettings, ThePlaneCrossesTheChosenAxisAtTheFraction) {
  const Scene scene = test::three_boxes();  // x 0..26, y 0..10, z 0..40
  ClipSettings s;
  EXPECT_FALSE(clip_plane(s, scene).has_value());
  s.enabled = true;
  s.axis = 2;
  s.position = 0.25f;
  std::optional<render::ClipPlane> p = clip_plane(s, scene);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->point.z, 10, 1e-9);
  EXPECT_DOUBLE_EQ(p->normal.z, 1);
  s.flip = true;
  s.axis = 0;
  s.position = 1;
  p = clip_plane(s, scene);
  EXPECT_NEAR(p->point.x, 26, 1e-9);
  EXPECT_DOUBLE_EQ(p->normal.x, -1);
  EXPECT_FALSE(clip_plane(s, Scene{}).has_value());
}

TEST(FileBrowser, FoldersFirstThenFilesSortedHiddenOnRequest) {
  const fs::path dir = segmesh::test::scratch_dir("viewer_browser");
  fs::create_directories(dir / "zeta");
  fs::create_directories(dir / "Alpha");
  std::ofstream(dir / "b.nii.gz") << "x";
  std::ofstream(dir / "A.glb") << "x";
  std::ofstream(dir / ".hidden") << "x";
  FolderListing l = list_folder(dir);
  EXPECT_TRUE(l.error.empty());
  ASSERT_EQ(l.entries.size(), 4u);
  EXPECT_EQ(l.entries[0].name, "Alpha");
  EXPECT_TRUE(l.entries[0].directory);
  EXPECT_EQ(l.entries[1].name, "zeta");
  EXPECT_EQ(l.entries[2].name, "A.glb");
  EXPECT_FALSE(l.entries[2].directory);
  EXPECT_EQ(l.entries[3].name, "b.nii.gz");
  EXPECT_EQ(list_folder(dir, true).entries.size(), 5u);
  EXPECT_EQ(parent_folder(l.folder), l.folder.parent_path());
  EXPECT_EQ(parent_folder(fs::path("/")), fs::path("/"));
  const FolderListing missing = list_folder(dir / "nope");
  EXPECT_FALSE(missing.error.empty());
  EXPECT_TRUE(missing.entries.empty());
}

}  // namespace
}  // namespace segmesh::viewer
