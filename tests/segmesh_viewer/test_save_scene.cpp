#include <gtest/gtest.h>

#include "segmesh/error.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_render/mat4.hpp"
#include "segmesh_viewer/move_history.hpp"
#include "segmesh_viewer/save_scene.hpp"
#include "support/test_support.hpp"
#include "viewer_test_support.hpp"

namespace segmesh::viewer {
namespace {

namespace fs = std::filesystem;

// Where the vertices of a part are drawn: its mesh moved by its transform.
std::vector<Vec3d> placed_positions(const Part& part) {
  std::vector<Vec3d> out;
  for (const Vec3f& p : part.mesh.positions) out.push_back(transform_point(part.transform, to_double(p)));
  return out;
}

TEST(SaveScene, TheSavedGlbHasTheMovedPositionsAndTheHiddenPartsMarked) {
  ViewerState state;
  set_scene(state, test::three_boxes(), {}, "boxes", nullptr);
  move_part(state, 2, PartPose{{0, -40, 5}, {0, 0, 30}});
  set_visible(state, 1, false);
  set_color(state, 0, Rgb{0.2f, 0.4f, 0.6f});
  const fs::path file = segmesh::test::scratch_dir("viewer_save") / "plan.glb";
  save_scene_glb(state, file);

  const Scene back = read_mesh(file);
  ASSERT_EQ(back.parts.size(), 3u);  // hidden parts are written, not left out
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.parts[i].name, state.scene.parts[i].name);
    const std::vector<Vec3d> expected = placed_positions(state.scene.parts[i]);
    const std::vector<Vec3d> got = placed_positions(back.parts[i]);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t v = 0; v < got.size(); ++v) {
      EXPECT_NEAR(got[v].x, expected[v].x, 1e-4);
      EXPECT_NEAR(got[v].y, expected[v].y, 1e-4);
      EXPECT_NEAR(got[v].z, expected[v].z, 1e-4);
    }
  }
  // The moved implant really is elsewhere than its unmoved mesh.
  EXPECT_NEAR(placed_positions(back.parts[2])[0].y - state.scene.parts[2].mesh.positions[0].y, -40, 3);
  EXPECT_TRUE(back.parts[0].visible);
  EXPECT_FALSE(back.parts[1].visible);
  EXPECT_TRUE(back.parts[2].visible);
  EXPECT_FLOAT_EQ(back.parts[0].material.base_color.g, 0.4f);
  EXPECT_EQ(back.parts[2].role, Role::implant);
}

TEST(SaveScene, AReopenedPlanCanBeResetToWhereItWasSaved) {
  ViewerState state;
  set_scene(state, test::three_boxes(), {}, "boxes", nullptr);
  move_part(state, 2, PartPose{{0, -40, 0}, {}});
  const fs::path file = segmesh::test::scratch_dir("viewer_reopen") / "plan.glb";
  save_scene_glb(state, file);

  ViewerState reopened;
  set_scene(reopened, read_mesh(file), {}, file.string(), nullptr);
  const Transform saved = reopened.scene.parts[2].transform;
  move_part(reopened, 2, PartPose{{7, 0, 0}, {}});
  reset_moves(reopened);
  EXPECT_EQ(reopened.scene.parts[2].transform, saved);
}

TEST(SaveScene, OnlyGlbIntoAnExistingFolder) {
  ViewerState state;
  set_scene(state, test::three_boxes(), {}, "boxes", nullptr);
  const fs::path dir = segmesh::test::scratch_dir("viewer_save_errors");
  EXPECT_THROW(save_scene_glb(state, dir / "plan.stl"), Error);
  EXPECT_THROW(save_scene_glb(state, dir / "missing" / "plan.glb"), Error);
  EXPECT_FALSE(fs::exists(dir / "plan.stl"));
  EXPECT_FALSE(fs::exists(dir / "missing"));
  ViewerState empty;
  EXPECT_THROW(save_scene_glb(empty, dir / "empty.glb"), Error);
  EXPECT_FALSE(fs::exists(dir / "empty.glb"));
}

}  // namespace
}  // namespace segmesh::viewer
