#include <gtest/gtest.h>

#include "segmesh_viewer/part_groups.hpp"
#include "segmesh_viewer/part_stats.hpp"
#include "viewer_test_support.hpp"

namespace segmesh::viewer {
namespace {

TEST(PartGroups, PartsAreGroupedByLabelInSceneOrder) {
  Scene scene = test::three_boxes();
  scene.parts.push_back(test::box_part("bone_3", 1, 3, Role::bone, {40, 0, 0}, {41, 1, 1}));
  const std::vector<PartGroup> groups = group_parts_by_label(scene);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].label, 1);
  EXPECT_EQ(groups[0].name, "bone");
  EXPECT_EQ(groups[0].role, Role::bone);
  EXPECT_EQ(groups[0].parts, (std::vector<size_t>{0, 1, 3}));
  EXPECT_EQ(groups[1].label, 2);
  EXPECT_EQ(groups[1].name, "implant");
  EXPECT_EQ(groups[1].parts, (std::vector<size_t>{2}));
}

TEST(PartGroups, NamesWithoutAComponentSuffixStayWhole) {
  Scene scene;
  scene.parts.push_back(test::box_part("left_femur", 7, 1, Role::bone, {0, 0, 0}, {1, 1, 1}));
  scene.parts.push_back(test::box_part("label3_x", 3, 1, Role::other, {0, 0, 0}, {1, 1, 1}));
  const std::vector<PartGroup> groups = group_parts_by_label(scene);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].name, "left_femur");  // "femur" is not a component number
  EXPECT_EQ(groups[1].name, "label3_x");
}

TEST(PartGroups, GroupVisibilityIsAllNoneOrMixed) {
  Scene scene = test::three_boxes();
  const PartGroup bone = group_parts_by_label(scene)[0];
  EXPECT_TRUE(group_all_visible(scene, bone));
  EXPECT_FALSE(group_none_visible(scene, bone));
  scene.parts[1].visible = false;
  EXPECT_FALSE(group_all_visible(scene, bone));
  EXPECT_FALSE(group_none_visible(scene, bone));
  scene.parts[0].visible = false;
  EXPECT_TRUE(group_none_visible(scene, bone));
}

TEST(PartStats, ABoxHasItsExactMeasures) {
  const PartStats s = measure_part(test::box_mesh({0, 0, 0}, {2, 3, 4}));
  EXPECT_EQ(s.vertices, 8);
  EXPECT_EQ(s.triangles, 12);
  EXPECT_NEAR(s.area_mm2, 2 * (6 + 8 + 12), 1e-9);
  EXPECT_NEAR(s.volume_mm3, 24, 1e-9);
  EXPECT_TRUE(s.closed);
  EXPECT_GT(s.rho_min, 0);
  EXPECT_LE(s.rho_min, s.rho_mean);
  int64_t counted = 0;
  for (int64_t c : s.rho_histogram) counted += c;
  EXPECT_EQ(counted, 12);
}

TEST(PartStats, AnOpenMeshIsNotClosed) {
  TriMesh m = test::box_mesh({0, 0, 0}, {1, 1, 1});
  m.indices.resize(m.indices.size() - 3);
  EXPECT_FALSE(measure_part(m).closed);
}

TEST(PartStats, CombiningSumsTheIncludedParts) {
  const std::vector<PartStats> stats = measure_parts(test::three_boxes());
  ASSERT_EQ(stats.size(), 3u);
  const PartStats all = combine_stats(stats, {true, false, true});
  EXPECT_EQ(all.triangles, 24);
  EXPECT_NEAR(all.volume_mm3, 10.0 * 10 * 40 + 2.0 * 6 * 20, 1e-6);
  EXPECT_DOUBLE_EQ(all.rho_min, std::min(stats[0].rho_min, stats[2].rho_min));
  EXPECT_NEAR(all.rho_mean, (stats[0].rho_mean + stats[2].rho_mean) / 2, 1e-12);
  EXPECT_TRUE(all.closed);
  const PartStats none = combine_stats(stats, {});
  EXPECT_EQ(none.triangles, 0);
  EXPECT_FALSE(none.closed);
}

}  // namespace
}  // namespace segmesh::viewer
