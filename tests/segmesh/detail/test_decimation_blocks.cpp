// The blocks of decimation's block phase (detail/decimation_blocks.hpp) and the room their
// moved triangle lists take (VertexTriangles::try_room): core vertices have every triangle in
// their block, each block owns the triangles with all corners in it, triangles along a border
// are locked, a collapse is in a block's core only when its neighbourhood is, and a list moves
// only into its block's room.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "segmesh/detail/decimation_blocks.hpp"

namespace segmesh {
namespace {

// A closed box of part 1, side 2n mm: an n x n grid of squares on each face, two triangles
// each.
LabelledSurface box(int n) {
  LabelledSurface s;
  std::vector<uint32_t> ids(size_t((n + 1) * (n + 1) * (n + 1)), ~0u);
  auto id = [&](int x, int y, int z) {
    uint32_t& v = ids[size_t((z * (n + 1) + y) * (n + 1) + x)];
    if (v == ~0u) {
      v = uint32_t(s.mesh.positions.size());
      s.mesh.positions.push_back({float(2 * x), float(2 * y), float(2 * z)});
    }
    return v;
  };
  // Each face as an origin and two directions.
  const int faces[6][9] = {{0, 0, 0, 0, 1, 0, 1, 0, 0}, {0, 0, 1, 1, 0, 0, 0, 1, 0},
                           {0, 0, 0, 1, 0, 0, 0, 0, 1}, {0, 1, 0, 0, 0, 1, 1, 0, 0},
                           {0, 0, 0, 0, 0, 1, 0, 1, 0}, {1, 0, 0, 0, 1, 0, 0, 0, 1}};
  for (const auto& f : faces)
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b) {
        auto at = [&](int i, int j) {
          return id(f[0] * n + i * f[3] + j * f[6], f[1] * n + i * f[4] + j * f[7],
                    f[2] * n + i * f[5] + j * f[8]);
        };
        const uint32_t p00 = at(a, b), p10 = at(a + 1, b), p11 = at(a + 1, b + 1),
                       p01 = at(a, b + 1);
        s.mesh.indices.insert(s.mesh.indices.end(), {p00, p10, p11, p00, p11, p01});
      }
  s.sides.assign(s.mesh.indices.size() / 3, {1, 0});
  s.part_count = 1;
  return s;
}

TEST(DecimationBlocks, CoreVerticesHaveEveryTriangleInTheirBlock) {
  LabelledSurface s = box(8);
  ASSERT_EQ(s.mesh.positions.size(), 386u);
  DecimationMesh m(s, false);
  const size_t nt = s.sides.size(), nv = s.mesh.positions.size();
  for (const double shift : {0.0, 0.5}) {
    const DecimationBlocks b = decimation_blocks(m, 7, shift, 2, 1 << 20);
    ASSERT_GE(b.count, 8u) << shift;
    // A core vertex's neighbours are in its block (core or on its border); the core vertices
    // are listed by block.
    size_t listed = 0;
    for (uint32_t k = 0; k < b.count; ++k) listed += b.vertices[k].size();
    size_t core = 0;
    std::vector<char> near(nv, 0);  // on or next to a border
    for (uint32_t v = 0; v < nv; ++v) {
      if (b.core[v] == DecimationBlocks::kBorder) {
        for (uint32_t t : m.tris[v])
          for (int c = 0; c < 3; ++c) near[s.mesh.indices[3 * t + c]] = 1;
        continue;
      }
      ++core;
      EXPECT_TRUE(
          std::binary_search(b.vertices[b.core[v]].begin(), b.vertices[b.core[v]].end(), v));
    }
    EXPECT_EQ(listed, core);
    EXPECT_GT(core, nv / 8) << shift;
    EXPECT_LT(core, nv) << shift;
    // Owned triangles: all three corners core of one block or on its border; every triangle
    // with a core corner is owned by that corner's block.
    int64_t with_core = 0, owned = 0, locked = 0;
    for (uint32_t k = 0; k < b.count; ++k) {
      owned += b.sides[2 * k + 1];
      EXPECT_EQ(b.sides[2 * k], 0);  // the background's sides are not counted
      EXPECT_LE(b.locked[k], b.sides[2 * k + 1]);
      locked += b.locked[k];
    }
    int64_t expect_locked_at_least = 0;
    for (size_t t = 0; t < nt; ++t) {
      const uint32_t* i = &s.mesh.indices[3 * t];
      bool has_core = false;
      for (int c = 0; c < 3; ++c) has_core = has_core || b.core[i[c]] != DecimationBlocks::kBorder;
      with_core += has_core;
      expect_locked_at_least += has_core && near[i[0]] + near[i[1]] + near[i[2]] >= 2;
      // An edge is in a block's core when both ends and all their neighbours are.
      for (int c = 0; c < 3; ++c) {
        const uint32_t u = i[c], v = i[(c + 1) % 3];
        for (uint32_t k = 0; k < b.count; ++k) {
          bool all = b.core[u] == k && b.core[v] == k;
          for (uint32_t x : {u, v})
            for (uint32_t t2 : m.tris[x])
              for (int c2 = 0; c2 < 3; ++c2) all = all && b.core[s.mesh.indices[3 * t2 + c2]] == k;
          EXPECT_EQ(in_block_core(m, b.core, u, v, k), all);
        }
      }
    }
    EXPECT_GE(owned, with_core);
    EXPECT_LE(owned, int64_t(nt));
    EXPECT_GE(locked, expect_locked_at_least);
  }
  // One cube over everything, or a grid larger than allowed: no blocks.
  EXPECT_EQ(decimation_blocks(m, 40, 0, 2, 1 << 20).count, 0u);
  EXPECT_EQ(decimation_blocks(m, 0.1, 0, 2, 1000).count, 0u);
}

TEST(DecimationBlocks, ListsMoveOnlyIntoTheirRoom) {
  LabelledSurface s = box(2);
  DecimationMesh m(s, false);
  const std::vector<uint32_t> before(m.tris[0].begin(), m.tris[0].end());
  const size_t size = before.size(), room_size = 2 * size + 16;
  VertexTriangles::Room room = m.tris.take_room(room_size);
  const size_t entries = m.tris.entries(), start = entries - room_size;
  // Within its room (four more than it started with) a list stays; beyond, it moves into the
  // block's room with twice the room, and the block's room then runs out.
  EXPECT_TRUE(m.tris.try_room(0, uint32_t(size + 4), room));
  EXPECT_EQ(room.next, start);
  EXPECT_TRUE(m.tris.try_room(0, uint32_t(size + 6), room));
  EXPECT_EQ(room.next, start + 2 * (size + 4));
  EXPECT_EQ(std::vector<uint32_t>(m.tris[0].begin(), m.tris[0].end()), before);
  EXPECT_FALSE(m.tris.try_room(1, 100, room));
  EXPECT_EQ(m.tris.entries(), entries);  // the pool did not grow
}

}  // namespace
}  // namespace segmesh
