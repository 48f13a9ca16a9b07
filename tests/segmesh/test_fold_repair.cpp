// Fold repair (detail/fold_repair.hpp): pairs of triangles near a junction that smoothing made
// cross are moved back toward their extracted positions until they no longer cross; nothing
// else moves.
#include <gtest/gtest.h>

#include "segmesh/detail/fold_repair.hpp"

namespace segmesh {
namespace {

TEST(FoldRepair, SegmentThroughTriangleInteriorOnly) {
  const Vec3d a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  EXPECT_TRUE(segment_crosses_triangle({0.2, 0.2, -1}, {0.2, 0.2, 1}, a, b, c));
  EXPECT_FALSE(segment_crosses_triangle({0.2, 0.2, 0.1}, {0.2, 0.2, 1}, a, b, c));  // above
  EXPECT_FALSE(segment_crosses_triangle({0.8, 0.8, -1}, {0.8, 0.8, 1}, a, b, c));   // outside
  EXPECT_FALSE(segment_crosses_triangle({0, 0, -1}, {0, 0, 1}, a, b, c));           // a corner
  EXPECT_FALSE(segment_crosses_triangle({0.1, 0.1, 0}, {0.3, 0.2, 0}, a, b, c));    // coplanar
}

// Two triangles of a junction's fan: a horizontal one and one that smoothing pushed down through
// it. Extracted, the second one stood above the first.
struct Fold {
  TriMesh mesh;
  std::vector<Vec3f> extracted;
  std::vector<SmoothRole> role;
};

Fold folded_pair() {
  Fold f;
  f.mesh.positions = {{0, 0, 0},      {2, 0, 0},     {0, 2, 0},      // the horizontal one
                      {0.4, 0.4, -1}, {0.6, 0.4, 1}, {0.4, 0.6, 1},  // pushed through it
                      {5, 5, 5},      {6, 5, 5},     {5, 6, 5}};     // far away, also moved
  f.mesh.indices = {0, 1, 2, 3, 4, 5, 6, 7, 8};
  f.extracted = f.mesh.positions;
  f.extracted[3] = {0.4, 0.4, 0.5};
  f.extracted[6] = {5, 5, 4};
  f.role.assign(9, SmoothRole::kSheet);
  f.role[0] = SmoothRole::kFixed;  // a junction corner
  f.role[3] = SmoothRole::kCurve;
  f.role[6] = SmoothRole::kCurve;
  return f;
}

TEST(FoldRepair, MovesTheCrossingPairBackUntilItNoLongerCrosses) {
  Fold f = folded_pair();
  ASSERT_TRUE(segment_crosses_triangle(to_double(f.mesh.positions[3]),
                                       to_double(f.mesh.positions[4]), {0, 0, 0}, {2, 0, 0},
                                       {0, 2, 0}));
  const size_t moved = repair_folds(f.mesh, f.extracted, f.role);
  EXPECT_EQ(moved, 6u);  // the six corners of the crossing pair
  // Vertex 3 went half-way back (z -0.25, still through it), then half of the rest (0.125), above
  // the horizontal triangle: nothing crosses any more.
  EXPECT_FLOAT_EQ(f.mesh.positions[3].z, 0.125f);
  EXPECT_FALSE(segment_crosses_triangle(to_double(f.mesh.positions[3]),
                                        to_double(f.mesh.positions[4]), {0, 0, 0}, {2, 0, 0},
                                        {0, 2, 0}));
  // The triangle that crossed nothing kept its smoothed position.
  EXPECT_FLOAT_EQ(f.mesh.positions[6].z, 5.0f);
}

// A fan folded over itself: two triangles on one junction corner, the second's far edge pushed
// through the first. Sharing a corner does not make a pair safe.
TEST(FoldRepair, FindsAFanFoldedOverItsCorner) {
  TriMesh mesh;
  mesh.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}};
  mesh.indices = {0, 1, 2, 0, 3, 4};
  std::vector<Vec3f> extracted = mesh.positions;
  extracted[3] = {0.5, 0.5, 0.5};  // the far edge stood above the first triangle
  std::vector<SmoothRole> role(5, SmoothRole::kSheet);
  role[0] = SmoothRole::kFixed;
  ASSERT_TRUE(segment_crosses_triangle(to_double(mesh.positions[3]), to_double(mesh.positions[4]),
                                       {0, 0, 0}, {2, 0, 0}, {0, 2, 0}));
  EXPECT_EQ(repair_folds(mesh, extracted, role), 5u);
  EXPECT_FALSE(segment_crosses_triangle(to_double(mesh.positions[3]), to_double(mesh.positions[4]),
                                        to_double(mesh.positions[0]), to_double(mesh.positions[1]),
                                        to_double(mesh.positions[2])));
}

TEST(FoldRepair, LeavesASurfaceWithoutCrossingsAsItIs) {
  Fold f = folded_pair();
  f.mesh.positions[3] = {0.4, 0.4, 0.25};
  const std::vector<Vec3f> before = f.mesh.positions;
  EXPECT_EQ(repair_folds(f.mesh, f.extracted, f.role), 0u);
  for (size_t v = 0; v < before.size(); ++v) EXPECT_EQ(f.mesh.positions[v].z, before[v].z);
}

TEST(FoldRepair, LooksOnlyNearJunctions) {
  Fold f = folded_pair();
  f.role.assign(9, SmoothRole::kSheet);  // no junction anywhere: one interface, left alone
  EXPECT_EQ(repair_folds(f.mesh, f.extracted, f.role), 0u);
}

}  // namespace
}  // namespace segmesh
