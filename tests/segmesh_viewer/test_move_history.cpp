#include <gtest/gtest.h>

#include "segmesh_render/camera.hpp"
#include "segmesh_render/mat4.hpp"
#include "segmesh_viewer/move_history.hpp"
#include "segmesh_viewer/part_pose.hpp"
#include "viewer_test_support.hpp"

namespace segmesh::viewer {
namespace {

ViewerState loaded_state() {
  ViewerState state;
  set_scene(state, test::three_boxes(), {}, "boxes", nullptr);
  return state;
}

Vec3d placed(const ViewerState& state, size_t part, size_t vertex) {
  return transform_point(state.scene.parts[part].transform,
                                 to_double(state.scene.parts[part].mesh.positions[vertex]));
}

void expect_near(Vec3d a, Vec3d b, double tol = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

TEST(MoveHistory, ATranslationMovesEveryVertexByIt) {
  ViewerState state = loaded_state();
  move_part(state, 2, PartPose{{0, -30, 5}, {}});
  for (size_t v = 0; v < 8; ++v) {
    expect_near(placed(state, 2, v), to_double(state.scene.parts[2].mesh.positions[v]) + Vec3d{0, -30, 5});
  }
  EXPECT_EQ(state.scene.parts[0].transform, identity_transform());  // the others stay
}

TEST(MoveHistory, ARotationTurnsThePartAboutItsCentre) {
  ViewerState state = loaded_state();
  move_part(state, 1, PartPose{{}, {0, 0, 90}});
  // bone_2 spans x 20..26, y 0..6 around the centre (23, 3): a quarter turn about z maps the
  // corner (20, 0) to (26, 0), (26, 0) to (26, 6).
  expect_near(placed(state, 1, 0), {26, 0, 0}, 1e-9);
  expect_near(placed(state, 1, 1), {26, 6, 0}, 1e-9);
  const render::Bounds b = render::transformed_bounds(render::mesh_bounds(state.scene.parts[1].mesh),
                                                      state.scene.parts[1].transform);
  expect_near(b.center(), {23, 3, 15}, 1e-9);
}

TEST(MoveHistory, UndoAndRedoRestoreTransformsExactly) {
  ViewerState state = loaded_state();
  const Transform start = state.scene.parts[2].transform;
  move_part(state, 2, PartPose{{0, -30, 0}, {}});
  const Transform first = state.scene.parts[2].transform;
  move_part(state, 2, PartPose{{0, -30, 0}, {15, 0, 0}});
  const Transform second = state.scene.parts[2].transform;
  ASSERT_NE(first, second);

  EXPECT_TRUE(undo(state));
  EXPECT_EQ(state.scene.parts[2].transform, first);
  EXPECT_TRUE(undo(state));
  EXPECT_EQ(state.scene.parts[2].transform, start);
  EXPECT_FALSE(undo(state));
  EXPECT_TRUE(redo(state));
  EXPECT_EQ(state.scene.parts[2].transform, first);
  EXPECT_TRUE(redo(state));
  EXPECT_EQ(state.scene.parts[2].transform, second);
  EXPECT_FALSE(redo(state));
}

TEST(MoveHistory, ANewMoveClearsRedo) {
  ViewerState state = loaded_state();
  move_part(state, 0, PartPose{{1, 0, 0}, {}});
  undo(state);
  ASSERT_TRUE(can_redo(state));
  move_part(state, 1, PartPose{{0, 2, 0}, {}});
  EXPECT_FALSE(can_redo(state));
  EXPECT_EQ(state.history.undo.size(), 1u);
}

TEST(MoveHistory, ADragIsOneStepAndAnUnchangedPoseNone) {
  ViewerState state = loaded_state();
  const PartPose before = state.views[2].pose;
  for (int k = 1; k <= 20; ++k) preview_pose(state, 2, PartPose{{0, -double(k), 0}, {}});
  EXPECT_FALSE(can_undo(state));  // previews are not recorded
  commit_move(state, 2, before);
  EXPECT_EQ(state.history.undo.size(), 1u);
  commit_move(state, 2, state.views[2].pose);  // nothing changed since
  EXPECT_EQ(state.history.undo.size(), 1u);
  undo(state);
  EXPECT_EQ(state.views[2].pose, before);
  EXPECT_EQ(state.scene.parts[2].transform, identity_transform());
}

TEST(MoveHistory, ResetMovesEveryPartBackAsOneUndoableStep) {
  ViewerState state = loaded_state();
  move_part(state, 0, PartPose{{3, 0, 0}, {}});
  move_part(state, 2, PartPose{{0, -30, 0}, {0, 10, 0}});
  const Transform moved0 = state.scene.parts[0].transform, moved2 = state.scene.parts[2].transform;
  EXPECT_TRUE(reset_moves(state));
  EXPECT_EQ(state.scene.parts[0].transform, identity_transform());
  EXPECT_EQ(state.scene.parts[2].transform, identity_transform());
  EXPECT_EQ(state.history.undo.size(), 3u);
  EXPECT_FALSE(reset_moves(state));  // nothing left to reset: no step recorded
  EXPECT_EQ(state.history.undo.size(), 3u);
  undo(state);
  EXPECT_EQ(state.scene.parts[0].transform, moved0);
  EXPECT_EQ(state.scene.parts[2].transform, moved2);
}

TEST(MoveHistory, ResetReturnsToTheTransformThePartWasLoadedWith) {
  Scene scene = test::three_boxes();
  Transform loaded = identity_transform();
  loaded[12] = 100;  // a saved plan: the implant was moved 100 mm along x
  scene.parts[2].transform = loaded;
  ViewerState state;
  set_scene(state, std::move(scene), {}, "plan.glb", nullptr);
  EXPECT_DOUBLE_EQ(state.views[2].pivot.x, 111);  // the centre where the part is
  move_part(state, 2, PartPose{{0, 5, 0}, {}});
  EXPECT_DOUBLE_EQ(placed(state, 2, 0).x, 110);
  EXPECT_DOUBLE_EQ(placed(state, 2, 0).y, 7);
  EXPECT_TRUE(reset_part(state, 2));
  EXPECT_EQ(state.scene.parts[2].transform, loaded);
}

TEST(MoveHistory, DraggingMovesThePointWithTheMouse) {
  render::Camera camera;
  camera.target = {0, 0, 0};
  camera.distance = 300;
  render::set_view(camera, render::StandardView::iso);
  const Vec3d at{10, -5, 20};
  const int w = 800, h = 600;
  const Vec3d start = *render::project_to_pixel(camera, w, h, at);
  const Vec3d moved = at + drag_translation(camera, h, 40, -25, at);
  const Vec3d end = *render::project_to_pixel(camera, w, h, moved);
  EXPECT_NEAR(end.x - start.x, 40, 0.5);
  EXPECT_NEAR(end.y - start.y, -25, 0.5);
  // In the view plane: the depth does not change.
  const render::CameraFrame f = render::camera_frame(camera);
  EXPECT_NEAR(dot(moved - at, f.forward), 0, 1e-9);
}

}  // namespace
}  // namespace segmesh::viewer
