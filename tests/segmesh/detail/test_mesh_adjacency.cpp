// Vertex adjacency (mesh_adjacency.hpp): corner rows are a complete, ordered transpose of the index
// array for any thread count; rings exist exactly for closed oriented manifold meshes and list
// each vertex's neighbours in fan order. Also: the parallel mesh measures built on them do not
// depend on the thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <set>
#include <vector>

#include "segmesh/marching_cubes.hpp"
#include "segmesh/detail/mesh_adjacency.hpp"
#include "segmesh/mesh_measures.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

// Marching Cubes of a random 0/1 field: closed, manifold, about 10^5 triangles, enough for the
// parallel chunked path (at least 2^16 triangles).
TriMesh random_blobs() { return marching_cubes(test::random_coins({48, 40, 40}, 11), {}); }

// Triangles as rotations starting at their smallest index, so (a, b, c) == (b, c, a).
std::set<std::array<uint32_t, 3>> triangle_set(const std::vector<uint32_t>& idx) {
  std::set<std::array<uint32_t, 3>> s;
  for (size_t t = 0; t < idx.size(); t += 3) {
    std::array<uint32_t, 3> a{idx[t], idx[t + 1], idx[t + 2]};
    std::rotate(a.begin(), std::min_element(a.begin(), a.end()), a.end());
    s.insert(a);
  }
  return s;
}

TEST(MeshAdjacency, CornerRowsHoldEveryCornerOnceInIncreasingOrder) {
  const TriMesh mesh = random_blobs();
  ASSERT_GT(mesh.triangle_count(), size_t{1} << 16);
  const auto rows = vertex_corners<uint32_t>(mesh.indices, mesh.positions.size());
  ASSERT_EQ(rows.offsets.size(), mesh.positions.size() + 1);
  ASSERT_EQ(rows.offsets.back(), mesh.indices.size());
  std::vector<int> seen(mesh.indices.size(), 0);
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    for (const uint32_t* c = rows.begin(v); c != rows.end(v); ++c) {
      ASSERT_EQ(mesh.indices[*c], v) << "corner " << *c << " is not at vertex " << v;
      if (c != rows.begin(v)) {
        ASSERT_LT(c[-1], c[0]) << "row " << v << " out of order";
      }
      ++seen[*c];
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
}

TEST(MeshAdjacency, CornerRowsAndRingsAreIdenticalForAnyThreadCount) {
  const TriMesh mesh = random_blobs();
  VertexRows<uint32_t> one, many;
  bool fans_one = false, fans_many = false;
  tbb::task_arena(1).execute([&] {
    one = vertex_corners<uint32_t>(mesh.indices, mesh.positions.size());
    fans_one = corners_to_rings(mesh.indices, one);
  });
  tbb::task_arena(4).execute([&] {
    many = vertex_corners<uint32_t>(mesh.indices, mesh.positions.size());
    fans_many = corners_to_rings(mesh.indices, many);
  });
  ASSERT_TRUE(fans_one);
  ASSERT_TRUE(fans_many);
  EXPECT_TRUE(std::equal(one.offsets.begin(), one.offsets.end(), many.offsets.begin(), many.offsets.end()));
  EXPECT_TRUE(std::equal(one.entries.begin(), one.entries.end(), many.entries.begin(), many.entries.end()));
}

TEST(MeshAdjacency, RingsOfAClosedMeshSpanExactlyItsTrianglesInFanOrder) {
  const TriMesh mesh = random_blobs();
  auto rows = vertex_corners<uint32_t>(mesh.indices, mesh.positions.size());
  ASSERT_TRUE(corners_to_rings(mesh.indices, rows));
  const auto triangles = triangle_set(mesh.indices);
  size_t spanned = 0;
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const size_t d = rows.size(v);
    const uint32_t* ring = rows.begin(v);
    ASSERT_TRUE(d == 0 || d >= 3) << "vertex " << v;
    std::set<uint32_t> distinct(ring, ring + d);
    ASSERT_EQ(distinct.size(), d) << "vertex " << v << " repeats a neighbour";
    for (size_t k = 0; k < d; ++k) {
      std::array<uint32_t, 3> t{static_cast<uint32_t>(v), ring[k], ring[(k + 1) % d]};
      std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
      ASSERT_TRUE(triangles.count(t)) << "(" << v << ", " << ring[k] << ", " << ring[(k + 1) % d]
                                      << ") is not a triangle of the mesh, wound as in it";
    }
    spanned += d;
  }
  EXPECT_EQ(spanned, mesh.indices.size());  // each triangle once at each of its corners
}

// The unit cube's 12 triangles, counter-clockwise from outside (as in test_mesh_measures.cpp).
std::vector<uint32_t> cube_indices() {
  return {0, 2, 1, 1, 2, 3, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3,
          0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5, 4, 5, 7, 4, 7, 6};
}

bool has_rings(const std::vector<uint32_t>& idx, size_t nv) {
  auto rows = vertex_corners<uint32_t>(idx, nv);
  return corners_to_rings(idx, rows);
}

TEST(MeshAdjacency, RingsOnlyForClosedOrientedManifolds) {
  EXPECT_TRUE(has_rings(cube_indices(), 8));

  std::vector<uint32_t> open = cube_indices();
  open.resize(30);  // top face missing: boundary edges
  EXPECT_FALSE(has_rings(open, 8));

  std::vector<uint32_t> flipped = cube_indices();
  std::swap(flipped[1], flipped[2]);  // one triangle wound the other way
  EXPECT_FALSE(has_rings(flipped, 8));

  // Two cubes sharing vertex 7 (a pinch point): every edge has two triangles, but vertex 7's
  // triangles form two fans.
  std::vector<uint32_t> pinch = cube_indices();
  for (uint32_t i : cube_indices()) pinch.push_back(i == 0 ? 7 : i + 8);
  EXPECT_FALSE(has_rings(pinch, 16));

  // A fin: a third triangle on an edge of the cube.
  std::vector<uint32_t> fin = cube_indices();
  fin.insert(fin.end(), {0, 1, 8});
  EXPECT_FALSE(has_rings(fin, 9));
}

TEST(MeshAdjacency, MeasuresAreIdenticalForAnyThreadCount) {
  const TriMesh mesh = random_blobs();
  MeshMeasures one, many;
  tbb::task_arena(1).execute([&] { one = measure_mesh(mesh); });
  tbb::task_arena(4).execute([&] { many = measure_mesh(mesh); });
  EXPECT_TRUE(one.closed());
  EXPECT_EQ(0, std::memcmp(&one, &many, sizeof(MeshMeasures)));
  double v1 = 0, v4 = 0;
  tbb::task_arena(1).execute([&] { v1 = enclosed_volume(mesh); });
  tbb::task_arena(4).execute([&] { v4 = enclosed_volume(mesh); });
  EXPECT_EQ(v1, v4);
  EXPECT_EQ(v1, one.volume_mm3);
}

}  // namespace
}  // namespace segmesh
