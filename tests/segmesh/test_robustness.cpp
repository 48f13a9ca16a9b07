// Robustness of the whole extraction path (issue 7) on the inputs that break meshers: empty
// labels, single voxels, parts at the volume border, one-voxel-thin walls and rods, parts that
// touch only along an edge or at a corner, random label noise, and grey-value volumes holding
// NaN or infinite values. For Marching Cubes and Dual Contouring, every connectivity, with and
// without smoothing, each part must be closed and edge-manifold with positive volume and finite
// coordinates — or the request must fail with a clear one-line message. (All of these already
// held when the tests were written: NaN grey values count as below the iso value, +inf as above,
// in component_field.cpp.)
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "segmesh/error.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/pipeline.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

Image grey_image(ScalarVolume v) {
  Image image;
  image.path = "grey.nii.gz";
  image.voxel_type = "float32";
  image.volume = std::move(v);
  return image;
}

LabelVolume labels(std::array<int64_t, 3> dims) {
  LabelVolume v;
  v.grid.dims = dims;
  v.grid.spacing = {0.7, 0.9, 1.3};
  v.voxels.assign(v.grid.voxel_count(), 0);
  return v;
}

struct Setting {
  Method method;
  int connectivity;
  bool smooth;
  std::string name() const {
    return std::string(method_name(method)) + " conn " + std::to_string(connectivity) +
           (smooth ? " smoothed" : " raw");
  }
  MeshingOptions options() const {
    MeshingOptions o;
    o.method = method;
    o.connectivity = connectivity;
    if (!smooth) o.smooth.method = SmoothMethod::none;
    return o;
  }
};

std::vector<Setting> all_settings() {
  std::vector<Setting> s;
  for (Method m : {Method::marching_cubes, Method::dual_contouring})
    for (int c : {6, 18, 26})
      for (bool smooth : {false, true}) s.push_back({m, c, smooth});
  return s;
}

bool finite(const Vec3f& p) {
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
}

// Every part closed, edge-manifold, consistently wound outwards, finite; returns the number of
// parts.
size_t expect_sound_scene(const Scene& scene, const std::string& what) {
  EXPECT_FALSE(scene.parts.empty()) << what;
  for (const Part& p : scene.parts) {
    const MeshMeasures m = measure_mesh(p.mesh);
    EXPECT_TRUE(m.closed()) << what << " " << p.name << ": boundary " << m.boundary_edges
                            << ", non-manifold " << m.nonmanifold_edges << ", winding "
                            << m.winding_errors << ", triangles " << m.triangles;
    EXPECT_GT(m.volume_mm3, 0) << what << " " << p.name;
    EXPECT_EQ(m.degenerate_triangles, 0) << what << " " << p.name;
    size_t bad = 0;
    for (const Vec3f& q : p.mesh.positions) bad += !finite(q);
    for (const Vec3f& n : p.mesh.normals) bad += !finite(n);
    EXPECT_EQ(bad, 0u) << what << " " << p.name << ": non-finite positions or normals";
  }
  return scene.parts.size();
}

// Runs `volume` through every setting; `parts(connectivity)` is the number of parts expected.
void check_all_settings(const LabelVolume& volume, const std::string& what,
                        const std::function<size_t(int)>& parts) {
  for (const Setting& s : all_settings()) {
    SCOPED_TRACE(what + ", " + s.name());
    Scene scene;
    ASSERT_NO_THROW(scene = build_scene(test::label_image(volume, "robust.nii.gz"), s.options()));
    EXPECT_EQ(expect_sound_scene(scene, what + ", " + s.name()), parts(s.connectivity));
  }
}

TEST(Robustness, SingleVoxelPartsAnywhereIncludingEveryCornerOfTheVolume) {
  LabelVolume v = labels({5, 6, 7});
  v.at(2, 3, 3) = 1;  // interior
  for (int64_t k : {0, 6})
    for (int64_t j : {0, 5})
      for (int64_t i : {0, 4}) v.at(i, j, k) = 2;  // the eight corners of the volume
  check_all_settings(v, "single voxels", [](int) { return size_t(9); });
}

TEST(Robustness, VolumeThatIsAllForegroundOrOneVoxel) {
  LabelVolume full = labels({4, 3, 5});
  std::fill(full.voxels.begin(), full.voxels.end(), 3);
  check_all_settings(full, "all foreground", [](int) { return size_t(1); });
  LabelVolume one = labels({1, 1, 1});
  one.voxels[0] = 1;
  check_all_settings(one, "1x1x1 volume", [](int) { return size_t(1); });
  LabelVolume flat = labels({6, 5, 1});  // a single slice
  for (int64_t i = 1; i < 5; ++i) flat.at(i, 2, 0) = 1;
  check_all_settings(flat, "one-slice volume", [](int) { return size_t(1); });
}

TEST(Robustness, OneVoxelThinWallsAndRodsAcrossTheWholeVolume) {
  LabelVolume wall = labels({8, 9, 10});
  for (int64_t k = 0; k < 10; ++k)
    for (int64_t i = 0; i < 8; ++i) wall.at(i, 4, k) = 1;  // touches four faces of the volume
  check_all_settings(wall, "thin wall", [](int) { return size_t(1); });

  LabelVolume rod = labels({7, 7, 9});
  for (int64_t k = 0; k < 9; ++k) rod.at(3, 3, k) = 1;
  check_all_settings(rod, "thin rod", [](int) { return size_t(1); });

  // A one-voxel-thin hollow box: a closed wall around a cavity gives two shells.
  LabelVolume box = labels({9, 9, 9});
  for (int64_t k = 1; k < 8; ++k)
    for (int64_t j = 1; j < 8; ++j)
      for (int64_t i = 1; i < 8; ++i) {
        const bool inner = i > 1 && i < 7 && j > 1 && j < 7 && k > 1 && k < 7;
        if (!inner) box.at(i, j, k) = 1;
      }
  check_all_settings(box, "hollow box", [](int) { return size_t(1); });
  for (Method m : {Method::marching_cubes, Method::dual_contouring}) {
    const Scene scene = build_scene(test::label_image(box, "robust.nii.gz"), {.method = m});
    EXPECT_EQ(measure_mesh(scene.parts[0].mesh).shells, 2) << method_name(m);
  }
}

TEST(Robustness, PartsTouchingOnlyAlongAnEdgeOrAtACorner) {
  // Offsets from (3,3,3): edge contact in each plane, corner contact along each diagonal.
  const std::array<std::array<int, 3>, 7> offsets = {
      {{1, 1, 0}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}, {-1, 1, 1}, {1, -1, 1}, {1, 1, -1}}};
  for (const auto& d : offsets) {
    const bool corner = d[0] != 0 && d[1] != 0 && d[2] != 0;
    // Same label: one part or two, by connectivity.
    LabelVolume same = labels({7, 7, 7});
    same.at(3, 3, 3) = 1;
    same.at(3 + d[0], 3 + d[1], 3 + d[2]) = 1;
    const std::string what = std::string(corner ? "corner" : "edge") + " contact " +
                             std::to_string(d[0]) + "," + std::to_string(d[1]) + "," +
                             std::to_string(d[2]);
    check_all_settings(same, what, [corner](int c) {
      return size_t(c == 6 || (corner && c == 18) ? 2 : 1);
    });
    // Different labels: always two parts, each closed on its own.
    LabelVolume other = same;
    other.at(3 + d[0], 3 + d[1], 3 + d[2]) = 2;
    check_all_settings(other, what + ", two labels", [](int) { return size_t(2); });
    // A 2x2x2 checkerboard block of edge and corner contacts at the volume's corner.
  }
  LabelVolume checker = labels({4, 4, 4});
  for (int64_t k = 0; k < 4; ++k)
    for (int64_t j = 0; j < 4; ++j)
      for (int64_t i = 0; i < 4; ++i) checker.at(i, j, k) = (i + j + k) % 2;
  check_all_settings(checker, "checkerboard", [](int c) { return size_t(c == 6 ? 32 : 1); });
}

TEST(Robustness, RandomLabelNoiseGivesClosedParts) {
  std::mt19937 random(7);
  for (int round = 0; round < 3; ++round) {
    LabelVolume v = labels({9, 8, 7});
    std::uniform_int_distribution<int> label(0, 3);
    for (int32_t& x : v.voxels) x = label(random) == 0 ? 0 : (random() % 3 == 0 ? 2 : 1);
    for (const Setting& s : all_settings()) {
      SCOPED_TRACE("noise round " + std::to_string(round) + ", " + s.name());
      const Scene scene = build_scene(test::label_image(v, "robust.nii.gz"), s.options());
      expect_sound_scene(scene, "noise, " + s.name());
    }
  }
}

TEST(Robustness, EmptyLabelsAreClearErrors) {
  LabelVolume v = labels({5, 5, 5});
  for (Method m : {Method::marching_cubes, Method::dual_contouring}) {
    try {
      build_scene(test::label_image(v, "robust.nii.gz"), {.method = m});
      ADD_FAILURE() << "an empty volume was meshed";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("robust.nii.gz: no foreground"), std::string::npos)
          << e.what();
    }
    v.at(2, 2, 2) = 1;
    try {
      build_scene(test::label_image(v, "robust.nii.gz"), {.method = m, .labels = {4}});
      ADD_FAILURE() << "a missing label was meshed";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("label 4 is not in the volume"), std::string::npos)
          << e.what();
    }
    v.at(2, 2, 2) = 0;
  }
}

// A ball of radius 4 in a grey-value ramp (1000 inside, -1000 outside), with NaN and infinite
// voxels scattered inside, on the surface and outside, and a slab of NaN at the volume's border.
ScalarVolume ball_with_non_finite_values() {
  ScalarVolume v;
  v.grid.dims = {20, 18, 16};
  v.grid.spacing = {0.8, 0.8, 1.0};
  v.voxels.assign(v.grid.voxel_count(), -1000.0f);
  for (int64_t k = 0; k < 16; ++k)
    for (int64_t j = 0; j < 18; ++j)
      for (int64_t i = 0; i < 20; ++i) {
        const double r = std::hypot((i - 10) * 0.8, (j - 9) * 0.8, (k - 8) * 1.0);
        v.at(i, j, k) = static_cast<float>(std::clamp(-500.0 * (r - 4), -1000.0, 1000.0));
      }
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  std::mt19937 random(3);
  for (size_t n = 0; n < v.voxels.size() / 20; ++n) {
    const size_t at = random() % v.voxels.size();
    v.voxels[at] = n % 3 == 0 ? nan : (n % 3 == 1 ? inf : -inf);
  }
  v.at(10, 9, 8) = nan;      // the centre
  v.at(10 + 5, 9, 8) = inf;  // just outside the surface
  v.at(10 - 5, 9, 8) = -inf;
  for (int64_t k = 0; k < 16; ++k)
    for (int64_t j = 0; j < 18; ++j) v.at(0, j, k) = nan;
  return v;
}

TEST(Robustness, NanAndInfiniteGreyValuesGiveClosedFiniteMeshes) {
  const ScalarVolume v = ball_with_non_finite_values();
  for (const Setting& s : all_settings()) {
    SCOPED_TRACE(s.name());
    MeshingOptions o = s.options();
    o.iso = 0;
    Scene scene;
    ASSERT_NO_THROW(scene = build_scene(grey_image(v), o));
    expect_sound_scene(scene, "NaN/inf, " + s.name());
    // The ball is there (NaN counts as below iso, +inf as above): its part is the largest.
    const MeshMeasures ball = measure_mesh(scene.parts.front().mesh);
    const double expected = 4.0 / 3.0 * 3.14159265358979 * 64;
    EXPECT_GT(ball.volume_mm3, 0.5 * expected);
    EXPECT_LT(ball.volume_mm3, 1.5 * expected);
  }
}

TEST(Robustness, AllNanVolumeOrNonFiniteIsoIsAClearError) {
  ScalarVolume v;
  v.grid.dims = {4, 4, 4};
  v.voxels.assign(64, std::numeric_limits<float>::quiet_NaN());
  for (double iso : {0.0, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    try {
      build_scene(grey_image(v), {.iso = iso});
      ADD_FAILURE() << "meshed an all-NaN volume at " << iso;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
  }
  // A finite volume at a non-finite iso value.
  const ScalarVolume ball = ball_with_non_finite_values();
  for (double iso : {std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity(),
                     -std::numeric_limits<double>::infinity()}) {
    try {
      build_scene(grey_image(ball), {.iso = iso});
      ADD_FAILURE() << "meshed at iso " << iso;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--iso"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace segmesh
