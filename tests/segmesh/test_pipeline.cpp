// The pipeline: parts from labels and grey values, world placement, names and roles, closedness
// at voxel contacts and volume borders, and the errors a user can meet.
#include "segmesh/pipeline.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "segmesh/error.hpp"
#include "segmesh/mesh_measures.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

using test::label_image;

LabelVolume empty_labels(std::array<int64_t, 3> dims) {
  LabelVolume v;
  v.grid.dims = dims;
  v.voxels.assign(v.grid.voxel_count(), 0);
  return v;
}

// A box of label 1 and a ball of label 2 on a rotated, anisotropic, shifted grid.
LabelVolume box_and_ball(const Mat3d& direction) {
  LabelVolume v = empty_labels({30, 26, 20});
  v.grid.spacing = {0.8, 0.6, 1.5};
  v.grid.origin = {-50, 20, 100};
  v.grid.direction = direction;
  for (int k = 3; k < 9; ++k)
    for (int j = 4; j < 20; ++j)
      for (int i = 2; i < 12; ++i) v.at(i, j, k) = 1;
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 26; ++j)
      for (int i = 0; i < 30; ++i) {
        const double x = (i - 21) * 0.8, y = (j - 13) * 0.6, z = (k - 12) * 1.5;
        if (x * x + y * y + z * z < 36) v.at(i, j, k) = 2;
      }
  return v;
}

struct Box {
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  void add(Vec3d p) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
};

Box label_world_box(const LabelVolume& v, int32_t label) {
  Box b;
  for (int64_t k = 0; k < v.grid.dims[2]; ++k)
    for (int64_t j = 0; j < v.grid.dims[1]; ++j)
      for (int64_t i = 0; i < v.grid.dims[0]; ++i)
        if (v.at(i, j, k) == label) b.add(v.grid.to_world({double(i), double(j), double(k)}));
  return b;
}

Box mesh_world_box(const TriMesh& m) {
  Box b;
  for (const Vec3f& p : m.positions) b.add(to_double(p));
  return b;
}

void expect_all_parts_closed(const Scene& scene) {
  for (const Part& p : scene.parts) {
    const MeshMeasures m = measure_mesh(p.mesh);
    EXPECT_TRUE(m.closed()) << p.name;
    EXPECT_GT(m.volume_mm3, 0) << p.name;
  }
}

TEST(Pipeline, PartsSitAtTheirLabelsInWorldSpaceOnRotatedAndMirroredGrids) {
  const double c = std::cos(0.4), s = std::sin(0.4);
  const Mat3d rotated{c, -s, 0, s, c, 0, 0, 0, 1};
  const Mat3d mirrored{c, -s, 0, s, c, 0, 0, 0, -1};  // LAS-like flip of the k axis
  for (const Mat3d& direction : {rotated, mirrored})
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    const LabelVolume v = box_and_ball(direction);
    const Scene scene = build_scene(label_image(v), {.method = method});
    ASSERT_EQ(scene.parts.size(), 2u);
    expect_all_parts_closed(scene);
    const double voxel = std::max({v.grid.spacing[0], v.grid.spacing[1], v.grid.spacing[2]});
    for (const Part& part : scene.parts) {
      const Box want = label_world_box(v, part.label);
      const Box got = mesh_world_box(part.mesh);
      EXPECT_NEAR(got.lo.x, want.lo.x, voxel) << part.name;
      EXPECT_NEAR(got.lo.y, want.lo.y, voxel) << part.name;
      EXPECT_NEAR(got.lo.z, want.lo.z, voxel) << part.name;
      EXPECT_NEAR(got.hi.x, want.hi.x, voxel) << part.name;
      EXPECT_NEAR(got.hi.y, want.hi.y, voxel) << part.name;
      EXPECT_NEAR(got.hi.z, want.hi.z, voxel) << part.name;
      // Marching Cubes at 0.5 keeps the voxel volume up to the chamfered edges and corners.
      const double volume = measure_mesh(part.mesh).volume_mm3;
      EXPECT_NEAR(volume, part.voxel_volume_mm3, 0.12 * part.voxel_volume_mm3) << part.name;
    }
  }
}

TEST(Pipeline, ReleasingFreesTheVoxelsAndMeshesTheSame) {
  Image kept = label_image(box_and_ball(identity3()));
  Image released = kept;
  const Scene a = build_scene(kept, {});
  const Scene b = build_scene_releasing(released, {});
  const auto& voxels = std::get<LabelVolume>(released.volume).voxels;
  EXPECT_TRUE(voxels.empty());
  EXPECT_EQ(voxels.capacity(), 0u) << "the voxels' memory is still held";
  EXPECT_EQ(std::get<LabelVolume>(kept.volume).voxels.size(), 30u * 26u * 20u);
  EXPECT_EQ(released.grid().dims, kept.grid().dims);
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (size_t p = 0; p < a.parts.size(); ++p) {
    EXPECT_EQ(a.parts[p].mesh.indices, b.parts[p].mesh.indices);
    ASSERT_EQ(a.parts[p].mesh.positions.size(), b.parts[p].mesh.positions.size());
    for (size_t i = 0; i < a.parts[p].mesh.positions.size(); ++i) {
      EXPECT_EQ(a.parts[p].mesh.positions[i].x, b.parts[p].mesh.positions[i].x);
      EXPECT_EQ(a.parts[p].mesh.positions[i].y, b.parts[p].mesh.positions[i].y);
      EXPECT_EQ(a.parts[p].mesh.positions[i].z, b.parts[p].mesh.positions[i].z);
    }
  }
}

TEST(Pipeline, NamesRolesAndMaterialsFromDefaultsAndLabelNames) {
  LabelVolume v = empty_labels({12, 12, 12});
  v.at(2, 2, 2) = 1;
  v.at(6, 6, 6) = 1;
  v.at(6, 7, 6) = 1;
  v.at(9, 2, 2) = 2;
  v.at(2, 9, 9) = 7;
  Scene scene = build_scene(label_image(v), {});
  ASSERT_EQ(scene.parts.size(), 4u);
  EXPECT_EQ(scene.parts[0].name, "label1_1");
  EXPECT_EQ(scene.parts[0].voxels, 2);  // the larger component of label 1 comes first
  EXPECT_EQ(scene.parts[1].name, "label1_2");
  EXPECT_EQ(scene.parts[0].role, Role::bone);
  EXPECT_EQ(scene.parts[2].role, Role::implant);
  EXPECT_FLOAT_EQ(scene.parts[2].material.metallic, 1.0f);
  EXPECT_FLOAT_EQ(scene.parts[2].material.roughness, 0.7f);
  EXPECT_GT(scene.parts[2].material.base_color.r, 0.5f);
  EXPECT_LT(scene.parts[2].material.base_color.g, 0.2f);
  EXPECT_EQ(scene.parts[3].role, Role::other);
  EXPECT_EQ(scene.parts[3].name, "label7_1");

  Image image = label_image(v);
  image.labels = {{.label = 7, .name = "file_name", .color = Rgb{0, 0, 1}}};
  MeshingOptions o;
  o.label_names = {{.label = 1, .name = "tibia", .role = Role::bone},
                   {.label = 2, .name = "screw", .role = Role::implant}};
  scene = build_scene(image, o);
  EXPECT_EQ(scene.parts[0].name, "tibia_1");
  EXPECT_EQ(scene.parts[2].name, "screw_1");
  EXPECT_EQ(scene.parts[3].name, "file_name_1");
  EXPECT_EQ(scene.parts[3].role, Role::other);
  EXPECT_FLOAT_EQ(scene.parts[3].material.base_color.b, 1.0f);
}

TEST(Pipeline, EdgeAndCornerContactsGiveOneClosedShellPerPart) {
  for (std::array<int, 3> offset : {std::array<int, 3>{1, 1, 0}, {1, 1, 1}, {-1, 1, 1}}) {
    LabelVolume v = empty_labels({6, 6, 6});
    v.at(2, 2, 2) = 1;
    v.at(2 + offset[0], 2 + offset[1], 2 + offset[2]) = 1;
    const bool corner = offset[2] != 0;
    for (int connectivity : {6, 18, 26}) {
      const Scene scene = build_scene(label_image(v), {.connectivity = connectivity});
      const size_t expected_parts = connectivity == 6 ? 2 : (corner && connectivity == 18 ? 2 : 1);
      ASSERT_EQ(scene.parts.size(), expected_parts) << connectivity;
      expect_all_parts_closed(scene);
      for (const Part& p : scene.parts) EXPECT_EQ(measure_mesh(p.mesh).shells, 1) << p.name;
    }
  }
}

TEST(Pipeline, PartsTouchingTheVolumeBorderAreClosed) {
  LabelVolume v = empty_labels({5, 6, 7});
  std::fill(v.voxels.begin(), v.voxels.end(), 1);  // the whole volume is foreground
  v.at(0, 0, 0) = 2;
  const Scene scene = build_scene(label_image(v), {});
  ASSERT_EQ(scene.parts.size(), 2u);
  expect_all_parts_closed(scene);
}

TEST(Pipeline, GreyValueVolumeAtIsoGivesClosedComponents) {
  Image image;
  image.path = "ct.nii.gz";
  image.voxel_type = "int16";
  LabelVolume ct = empty_labels({40, 40, 30});
  ct.grid.spacing = {0.5, 0.5, 1.0};
  for (int64_t k = 0; k < 30; ++k)
    for (int64_t j = 0; j < 40; ++j)
      for (int64_t i = 0; i < 40; ++i) {
        const double r1 = std::hypot((i - 12) * 0.5, (j - 20) * 0.5, (k - 15) * 1.0);
        const double r2 = std::hypot((i - 30) * 0.5, (j - 20) * 0.5, (k - 15) * 1.0);
        // Two balls of 1000 "HU" in -1000, with a linear ramp over 2 mm at their surfaces.
        const double d = std::min(r1 - 4, r2 - 3);
        ct.at(i, j, k) = static_cast<int32_t>(std::lround(std::clamp(-500.0 * d, -1000.0, 1000.0)));
      }
  image.volume = ct;
  const Scene scene = build_scene(image, {.iso = 0});
  ASSERT_EQ(scene.parts.size(), 2u);
  expect_all_parts_closed(scene);
  EXPECT_EQ(scene.parts[0].name, "iso0_1");
  const double pi = 3.14159265358979;
  EXPECT_NEAR(measure_mesh(scene.parts[0].mesh).volume_mm3, 4.0 / 3 * pi * 64, 0.03 * 4.0 / 3 * pi * 64);
  EXPECT_NEAR(measure_mesh(scene.parts[1].mesh).volume_mm3, 4.0 / 3 * pi * 27, 0.05 * 4.0 / 3 * pi * 27);  // 3 slices per radius
}

TEST(Pipeline, PresmoothingKeepsPartsClosedAndCostsLittleVolumeOnThickParts) {
  const LabelVolume v = box_and_ball(identity3());
  const Scene plain = build_scene(label_image(v), {});
  for (Method method : {Method::marching_cubes, Method::dual_contouring}) {
    const Scene smooth = build_scene(label_image(v), {.method = method, .volume_sigma_mm = 0.6});
    ASSERT_EQ(smooth.parts.size(), plain.parts.size());
    expect_all_parts_closed(smooth);
    for (size_t p = 0; p < smooth.parts.size(); ++p) {
      const double before = measure_mesh(plain.parts[p].mesh).volume_mm3;
      const double after = measure_mesh(smooth.parts[p].mesh).volume_mm3;
      EXPECT_LT(after, before) << "smoothing a convex part shrinks it";
      EXPECT_GT(after, 0.85 * before);
    }
  }
  EXPECT_THROW(build_scene(label_image(v), {.volume_sigma_mm = -1}), Error);
  EXPECT_THROW(build_scene(label_image(v), {.dc_svd_eps = 2}), Error);
}

TEST(Pipeline, MinVoxelsDropsSpecksAndCountsThem) {
  LabelVolume v = empty_labels({10, 10, 10});
  for (int i = 1; i < 6; ++i) v.at(i, 2, 2) = 1;
  v.at(8, 8, 8) = 1;
  PipelineStats t;
  const Scene scene = build_scene(label_image(v), {.min_voxels = 2}, null_progress(), &t);
  ASSERT_EQ(scene.parts.size(), 1u);
  EXPECT_EQ(scene.parts[0].voxels, 5);
  EXPECT_EQ(t.dropped_components, 1);
  EXPECT_THROW(build_scene(label_image(v), {.min_voxels = 100}), Error);
}

void expect_error(const Image& image, const MeshingOptions& o, const std::string& fragment) {
  try {
    build_scene(image, o);
    ADD_FAILURE() << "no error; expected one containing \"" << fragment << "\"";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(Pipeline, RequestsTheVolumeCannotSatisfyAreClearErrors) {
  LabelVolume v = empty_labels({6, 6, 6});
  expect_error(label_image(v), {}, "test.nii.gz: no foreground");
  v.at(2, 2, 2) = 1;
  v.at(3, 3, 3) = 2;
  expect_error(label_image(v), {.labels = {5}}, "label 5 is not in the volume (labels present: 1, 2)");
  expect_error(label_image(v), {.connectivity = 8}, "--connectivity must be 6, 18 or 26");
  expect_error(label_image(v), {.labels = {1}, .iso = 0.5}, "--labels and --iso");
  expect_error(label_image(v), {.iso = 5}, "no voxel reaches --iso 5 (values range from 0 to 2)");

  Image floats;
  floats.path = "map.mrc";
  floats.voxel_type = "float32";
  ScalarVolume s;
  s.grid.dims = {4, 4, 4};
  s.voxels.assign(64, 0.5f);
  floats.volume = s;
  expect_error(floats, {}, "map.mrc: float32 values are not labels; give --iso VALUE");

  LabelVolume ct = empty_labels({20, 20, 4});
  for (size_t i = 0; i < ct.voxels.size(); ++i) ct.voxels[i] = static_cast<int32_t>(i) - 800;
  expect_error(label_image(ct), {}, "looks like a grey-value image");
}

TEST(Pipeline, CancelledProgressStopsTheRun) {
  struct CancelNow : Progress {
    bool cancelled() const override { return true; }
  } cancel;
  LabelVolume v = empty_labels({6, 6, 6});
  v.at(2, 2, 2) = 1;
  EXPECT_THROW(build_scene(label_image(v), {}, cancel), Cancelled);
}

}  // namespace
}  // namespace segmesh
