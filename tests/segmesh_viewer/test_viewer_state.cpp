#include <gtest/gtest.h>

#include "segmesh_viewer/move_history.hpp"
#include "segmesh_viewer/viewer_state.hpp"
#include "viewer_test_support.hpp"

namespace segmesh::viewer {
namespace {

ViewerState loaded_state() {
  ViewerState state;
  set_scene(state, test::three_boxes(), {}, "boxes.glb", nullptr);
  return state;
}

TEST(ViewerState, SetSceneMeasuresPartsAndCentresPivots) {
  const ViewerState state = loaded_state();
  ASSERT_EQ(state.views.size(), 3u);
  ASSERT_EQ(state.stats.size(), 3u);
  EXPECT_EQ(state.stats[0].triangles, 12);
  EXPECT_NEAR(state.stats[0].volume_mm3, 10.0 * 10 * 40, 1e-6);
  EXPECT_DOUBLE_EQ(state.views[1].pivot.x, 23);
  EXPECT_DOUBLE_EQ(state.views[1].pivot.y, 3);
  EXPECT_DOUBLE_EQ(state.views[1].pivot.z, 15);
  EXPECT_EQ(state.selected, -1);
  EXPECT_EQ(state.source, "boxes.glb");
}

TEST(ViewerState, SetSceneReplacesSelectionHistoryAndOpacity) {
  ViewerState state = loaded_state();
  select_part(state, 2);
  set_opacity(state, 0, 0.3f);
  move_part(state, 1, PartPose{{5, 0, 0}, {}});
  ASSERT_TRUE(can_undo(state));
  set_scene(state, test::three_boxes(), {}, "again.glb", nullptr);
  EXPECT_EQ(state.selected, -1);
  EXPECT_FALSE(can_undo(state));
  EXPECT_FLOAT_EQ(state.views[0].opacity, 1);
  EXPECT_EQ(state.views[1].pose, PartPose{});
}

TEST(ViewerState, SelectionIgnoresIndicesOutOfRange) {
  ViewerState state = loaded_state();
  select_part(state, 1);
  EXPECT_EQ(state.selected, 1);
  select_part(state, 3);
  EXPECT_EQ(state.selected, -1);
  select_part(state, 2);
  select_part(state, -5);
  EXPECT_EQ(state.selected, -1);
}

TEST(ViewerState, HidingTheSelectedPartClearsTheSelection) {
  ViewerState state = loaded_state();
  select_part(state, 2);
  set_visible(state, 1, false);
  EXPECT_EQ(state.selected, 2);
  EXPECT_FALSE(state.scene.parts[1].visible);
  set_visible(state, 2, false);
  EXPECT_EQ(state.selected, -1);
  set_visible(state, 2, true);
  EXPECT_TRUE(state.scene.parts[2].visible);
}

TEST(ViewerState, OpacityIsClampedAndHandedToTheRenderer) {
  ViewerState state = loaded_state();
  set_opacity(state, 0, 1.7f);
  set_opacity(state, 1, -2.0f);
  set_opacity(state, 2, 0.25f);
  set_opacity(state, 9, 0.5f);  // out of range: ignored
  const std::vector<float> opacity = render_opacity(state);
  ASSERT_EQ(opacity.size(), 3u);
  EXPECT_FLOAT_EQ(opacity[0], 1);
  EXPECT_FLOAT_EQ(opacity[1], 0);
  EXPECT_FLOAT_EQ(opacity[2], 0.25f);
}

TEST(ViewerState, ColourEditsTheMaterial) {
  ViewerState state = loaded_state();
  set_color(state, 2, Rgb{0.1f, 0.2f, 0.9f});
  EXPECT_FLOAT_EQ(state.scene.parts[2].material.base_color.b, 0.9f);
  EXPECT_FLOAT_EQ(state.scene.parts[2].material.metallic, 1);  // the rest of the material stays
}

}  // namespace
}  // namespace segmesh::viewer
