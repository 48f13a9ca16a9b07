// Decimation's working state (detail/decimation_mesh.hpp): without an error bound there are no
// witnesses, and the one collapse their check refused even then, a closed piece of the surface
// collapsed to nothing, is still refused; any other collapse passes, as it did with them.
#include "segmesh/detail/decimation_mesh.hpp"

#include <gtest/gtest.h>

#include <limits>

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

}  // namespace
}  // namespace segmesh
