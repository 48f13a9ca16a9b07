// Mesh measures on hand-made meshes whose answers are known: a closed cube (exact volume, area,
// Euler characteristic), a pinch point (two tetrahedra sharing a vertex), a fin (three triangles on
// one edge), an open box, a flipped triangle and degenerate triangles.
#include <gtest/gtest.h>

#include <cmath>

#include "segmesh/mesh_measures.hpp"

namespace segmesh {
namespace {

// The unit cube [0,1]^3 moved by `offset`, 12 triangles wound counter-clockwise from outside.
// Vertex i has coordinates (i & 1, i >> 1 & 1, i >> 2 & 1). The top face (z = 1) is the last two
// triangles, so `open_top` leaves it out.
TriMesh unit_cube(Vec3f offset = {}, bool open_top = false) {
  TriMesh m;
  for (uint32_t i = 0; i < 8; ++i) {
    m.positions.push_back(
        {offset.x + float(i & 1), offset.y + float(i >> 1 & 1), offset.z + float(i >> 2 & 1)});
  }
  m.indices = {0, 2, 1, 1, 2, 3,   // z = 0, normal -z
               0, 1, 5, 0, 5, 4,   // y = 0, normal -y
               2, 6, 7, 2, 7, 3,   // y = 1, normal +y
               0, 4, 6, 0, 6, 2,   // x = 0, normal -x
               1, 3, 7, 1, 7, 5,   // x = 1, normal +x
               4, 5, 7, 4, 7, 6};  // z = 1, normal +z
  if (open_top) m.indices.resize(30);
  return m;
}

// A tetrahedron with apex `apex` over the base (b0, b1, b2), the base wound so its normal points
// away from the apex, appended to `m` with its own vertices; the apex is m's vertex
// `shared_apex` when that is not -1.
void add_tetrahedron(TriMesh& m, Vec3f apex, Vec3f b0, Vec3f b1, Vec3f b2,
                     int64_t shared_apex = -1) {
  uint32_t a;
  if (shared_apex >= 0) {
    a = static_cast<uint32_t>(shared_apex);
  } else {
    a = static_cast<uint32_t>(m.positions.size());
    m.positions.push_back(apex);
  }
  const auto b = static_cast<uint32_t>(m.positions.size());
  m.positions.insert(m.positions.end(), {b0, b1, b2});
  m.indices.insert(m.indices.end(), {b, b + 1, b + 2,  // base, seen from below
                                     a, b + 1, b, a, b + 2, b + 1, a, b, b + 2});
}

TEST(MeshMeasures, ClosedUnitCube) {
  const MeshMeasures m = measure_mesh(unit_cube());
  EXPECT_EQ(m.vertices, 8);
  EXPECT_EQ(m.triangles, 12);
  EXPECT_EQ(m.edges, 18);
  EXPECT_DOUBLE_EQ(m.volume_mm3, 1.0);
  EXPECT_DOUBLE_EQ(m.area_mm2, 6.0);
  EXPECT_NEAR(m.mean_edge_length_mm, (12 + 6 * std::sqrt(2.0)) / 18, 1e-15);
  EXPECT_EQ(m.euler, 2);
  EXPECT_EQ(m.shells, 1);
  EXPECT_EQ(m.boundary_edges, 0);
  EXPECT_EQ(m.nonmanifold_edges, 0);
  EXPECT_EQ(m.nonmanifold_vertices, 0);
  EXPECT_EQ(m.winding_errors, 0);
  EXPECT_EQ(m.degenerate_triangles, 0);
  EXPECT_TRUE(m.closed());

  // Far from the origin the volume is still exact: a closed surface's volume does not depend on
  // the reference point, and the sums are taken about the centroid.
  const MeshMeasures far = measure_mesh(unit_cube({1000.5f, -500.25f, 200}));
  EXPECT_NEAR(far.volume_mm3, 1.0, 1e-12);
  EXPECT_NEAR(far.area_mm2, 6.0, 1e-12);

  // Wound the other way round: the same topology, negative volume, no winding errors (the
  // winding is consistent, only inward).
  TriMesh inside_out = unit_cube();
  for (size_t t = 0; t < 12; ++t)
    std::swap(inside_out.indices[3 * t + 1], inside_out.indices[3 * t + 2]);
  const MeshMeasures r = measure_mesh(inside_out);
  EXPECT_DOUBLE_EQ(r.volume_mm3, -1.0);
  EXPECT_EQ(r.winding_errors, 0);
  EXPECT_TRUE(r.closed());
}

TEST(MeshMeasures, TwoTetrahedraSharingAVertexPinch) {
  TriMesh m;
  add_tetrahedron(m, {0, 0, 0}, {-1, -1, -1}, {-1, 1, -1}, {1, 0, -1});  // below the tip
  add_tetrahedron(m, {0, 0, 0}, {-1, -1, 1}, {1, 0, 1}, {-1, 1, 1}, 0);  // above, same tip
  const MeshMeasures s = measure_mesh(m);
  EXPECT_EQ(s.vertices, 7);
  EXPECT_EQ(s.triangles, 8);
  EXPECT_EQ(s.edges, 12);
  EXPECT_EQ(s.boundary_edges, 0);
  EXPECT_EQ(s.nonmanifold_edges, 0);
  EXPECT_EQ(s.winding_errors, 0);
  EXPECT_EQ(s.nonmanifold_vertices, 1);  // the shared tip: two fans
  EXPECT_EQ(s.shells, 1);                // connected through the tip
  EXPECT_EQ(s.euler, 3);
  // Each tetrahedron: base area 2 times height 1 over 3. Both wound outwards.
  EXPECT_NEAR(s.volume_mm3, 2 * 2.0 / 3, 1e-12);
  EXPECT_TRUE(s.closed());  // closed() is about edges; the pinch is reported separately
}

TEST(MeshMeasures, ThreeTrianglesOnOneEdge) {
  TriMesh m;
  m.positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {-1, 1, 0}, {-1, -1, 0}};
  m.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  const MeshMeasures s = measure_mesh(m);
  EXPECT_EQ(s.vertices, 5);
  EXPECT_EQ(s.edges, 7);
  EXPECT_EQ(s.nonmanifold_edges, 1);
  EXPECT_EQ(s.boundary_edges, 6);
  EXPECT_EQ(s.winding_errors, 0);
  // Around each end of the fin edge the three triangles are linked through it: one fan.
  EXPECT_EQ(s.nonmanifold_vertices, 0);
  EXPECT_EQ(s.shells, 1);
  EXPECT_EQ(s.euler, 5 - 7 + 3);
  EXPECT_FALSE(s.closed());
}

TEST(MeshMeasures, OpenBoxHasBoundaryEdgesAndAnOriginBasedVolume) {
  const MeshMeasures s = measure_mesh(unit_cube({}, true));
  EXPECT_EQ(s.vertices, 8);
  EXPECT_EQ(s.triangles, 10);
  EXPECT_EQ(s.edges, 17);  // the top face's diagonal is gone
  EXPECT_EQ(s.boundary_edges, 4);
  EXPECT_EQ(s.nonmanifold_edges, 0);
  EXPECT_EQ(s.nonmanifold_vertices, 0);
  EXPECT_EQ(s.euler, 1);
  EXPECT_EQ(s.shells, 1);
  EXPECT_DOUBLE_EQ(s.area_mm2, 5.0);
  EXPECT_FALSE(s.closed());
  // Without its lid (flux (1/3) z = 1/3 through it) the box's divergence sum is 1 - 1/3 about
  // the origin; three units higher the lid would carry 4/3 and the bottom -1: -1/3. This is the
  // origin-based value every tool reports (mesh_metrics.py, VTK).
  EXPECT_NEAR(s.volume_mm3, 2.0 / 3, 1e-12);
  EXPECT_NEAR(measure_mesh(unit_cube({0, 0, 3}, true)).volume_mm3, -1.0 / 3, 1e-12);
}

TEST(MeshMeasures, FlippedTriangleGivesWindingErrors) {
  TriMesh m = unit_cube();
  std::swap(m.indices[4], m.indices[5]);  // triangle 1 of the bottom face
  const MeshMeasures s = measure_mesh(m);
  EXPECT_EQ(s.winding_errors, 3);  // each of its edges now runs the same way as its neighbour's
  EXPECT_EQ(s.boundary_edges, 0);
  EXPECT_EQ(s.nonmanifold_edges, 0);
  EXPECT_EQ(s.nonmanifold_vertices, 0);
  EXPECT_EQ(s.euler, 2);
  EXPECT_FALSE(s.closed());
}

TEST(MeshMeasures, DegenerateTriangles) {
  // Collinear corners: zero area, three boundary edges.
  TriMesh line;
  line.positions = {{0, 0, 0}, {1, 0, 0}, {3, 0, 0}};
  line.indices = {0, 1, 2};
  const MeshMeasures a = measure_mesh(line);
  EXPECT_EQ(a.degenerate_triangles, 1);
  EXPECT_EQ(a.area_mm2, 0.0);
  EXPECT_EQ(a.edges, 3);
  EXPECT_EQ(a.boundary_edges, 3);
  EXPECT_NEAR(a.mean_edge_length_mm, 2.0, 1e-15);

  // A repeated index: an edge from vertex 0 to itself (length 0, used once) and edge {0, 1} used
  // there and back. Vertex 0 counts as non-manifold, as in mesh_metrics.py.
  TriMesh repeated;
  repeated.positions = {{0, 0, 0}, {1, 0, 0}};
  repeated.indices = {0, 0, 1};
  const MeshMeasures b = measure_mesh(repeated);
  EXPECT_EQ(b.vertices, 2);
  EXPECT_EQ(b.degenerate_triangles, 1);
  EXPECT_EQ(b.edges, 2);
  EXPECT_EQ(b.boundary_edges, 1);
  EXPECT_EQ(b.winding_errors, 0);
  EXPECT_EQ(b.nonmanifold_edges, 0);
  EXPECT_EQ(b.nonmanifold_vertices, 1);
  EXPECT_NEAR(b.mean_edge_length_mm, 0.5, 1e-15);
  EXPECT_EQ(b.euler, 1);

  // A degenerate triangle glued onto the cube's bottom edge {0, 1}: that edge is now used three
  // times, the cube is no longer closed, and the extra triangle adds no area.
  TriMesh glued = unit_cube();
  glued.positions.push_back({0.5f, 0, 0});
  glued.indices.insert(glued.indices.end(), {0, 1, 8});
  const MeshMeasures c = measure_mesh(glued);
  EXPECT_EQ(c.degenerate_triangles, 1);
  EXPECT_NEAR(c.area_mm2, 6.0, 1e-12);
  EXPECT_EQ(c.nonmanifold_edges, 1);
  EXPECT_EQ(c.boundary_edges, 2);
  EXPECT_FALSE(c.closed());
}

TEST(MeshMeasures, EmptyMeshAndUnusedVertices) {
  const MeshMeasures e = measure_mesh(TriMesh{});
  EXPECT_EQ(e.vertices, 0);
  EXPECT_EQ(e.triangles, 0);
  EXPECT_FALSE(e.closed());
  // Unused vertices count nowhere: not in vertices, not in Euler, not as shells.
  TriMesh m = unit_cube();
  m.positions.push_back({5, 5, 5});
  const MeshMeasures s = measure_mesh(m);
  EXPECT_EQ(s.vertices, 8);
  EXPECT_EQ(s.euler, 2);
  EXPECT_EQ(s.shells, 1);
  EXPECT_NEAR(s.volume_mm3, 1.0, 1e-12);
}

}  // namespace
}  // namespace segmesh
