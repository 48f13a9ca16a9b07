// Decimation's working state (detail/decimation_mesh.hpp): without an error bound there are no
// witnesses, and the one collapse their check refused even then, a closed piece of the surface
// collapsed to nothing, is still refused; any other collapse passes, as it did with them. With a
// bound, points are measured against the surface as it was, whatever has moved since.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "segmesh/detail/decimation_mesh.hpp"

namespace segmesh {
namespace {

constexpr double kNoBound = std::numeric_limits<double>::infinity();

// A closed surface of part 1 against the background: `indices` over `positions`.
LabelledSurface closed(std::vector<Vec3f> positions, std::vector<uint32_t> indices) {
  LabelledSurface s;
  s.mesh.positions = std::move(positions);
  s.mesh.indices = std::move(indices);
  s.sides.assign(s.mesh.indices.size() / 3, {1, 0});
  s.part_count = 1;
  return s;
}

TEST(DecimationMesh, WithoutWitnessesAPieceIsStillNotCollapsedToNothing) {
  // Two triangles on the same three corners, wound both ways: a closed piece with no triangle
  // off the edge (1, 0).
  const LabelledSurface pillow =
      closed({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2, 0, 2, 1});
  // A tetrahedron: collapsing an edge leaves two triangles around the merged vertex.
  const LabelledSurface tetrahedron = closed({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                                             {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3});
  for (bool witnessing : {true, false}) {
    LabelledSurface a = pillow, b = tetrahedron;
    DecimationMesh p(a, witnessing), t(b, witnessing);
    EXPECT_EQ(p.witnessing, witnessing);
    EXPECT_FALSE(p.collapse_keeps_witnesses(1, 0, p.pos[0], kNoBound)) << witnessing;
    EXPECT_TRUE(t.collapse_keeps_witnesses(1, 0, t.pos[0], kNoBound)) << witnessing;
    // A vertex moved keeps every witness when there is no bound.
    EXPECT_TRUE(t.collapse_keeps_witnesses(3, 3, {0.1, 0.1, 2}, kNoBound)) << witnessing;
  }
}

TEST(DecimationMesh, NearOriginalMeasuresAgainstTheSurfaceAsItWas) {
  // An octahedron |x| + |y| + |z| = 1: the face x, y, z > 0 has the unit normal (1, 1, 1) / sqrt 3.
  const LabelledSurface octahedron =
      closed({{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}},
             {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5});
  const Vec3d centre{1.0 / 3, 1.0 / 3, 1.0 / 3};
  const Vec3d out = centre + (0.3 / std::sqrt(3.0)) * Vec3d{1, 1, 1};  // 0.3 off the face
  LabelledSurface a = octahedron;
  DecimationMesh m(a, true);
  EXPECT_TRUE(m.near_original(centre, 1e-12, 4));
  EXPECT_FALSE(m.near_original(out, 0.2 * 0.2, 4));
  EXPECT_TRUE(m.near_original(out, 0.31 * 0.31, 4));
  // From a vertex on the far side (its hint there): the same answers.
  EXPECT_FALSE(m.near_original(out, 0.2 * 0.2, 1));
  EXPECT_TRUE(m.near_original(out, 0.31 * 0.31, 1));
  // The working positions move; the original surface does not.
  m.pos[0] = {3, 0, 0};
  a.mesh.positions[0] = {3, 0, 0};
  EXPECT_FALSE(m.near_original({2, 0, 0}, 0.5 * 0.5, 0));
  // Without a bound there is nothing to keep: every point passes.
  LabelledSurface b = octahedron;
  DecimationMesh free_mesh(b, false);
  EXPECT_TRUE(free_mesh.near_original(out, 0.2 * 0.2, 4));
}

}  // namespace
}  // namespace segmesh
