// How many edges of one mesh pass through a triangle of another: the tests' independent count of
// crossing triangles between two parts (the library's fold repair has its own search; both use
// segment_crosses_triangle's definition: strictly through the interior, so triangles that share a
// corner or an edge, or lie on each other, do not count).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh::test {

// How many edges of one mesh cross a triangle of the other, both ways (candidates from a grid of
// 1 mm cells over the second mesh's triangle boxes; a pair met in several cells counts once per
// cell, which keeps zero zero).
inline size_t crossings(const TriMesh& m1, const TriMesh& m2) {
  auto corner = [](const TriMesh& m, size_t t, int k) {
    return to_double(m.positions[m.indices[3 * t + size_t(k)]]);
  };
  auto cells = [&](const TriMesh& m, size_t t, auto&& visit) {
    Vec3d lo = corner(m, t, 0), hi = lo;
    for (int k = 1; k < 3; ++k) {
      const Vec3d v = corner(m, t, k);
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
    for (int64_t z = int64_t(std::floor(lo.z)); z <= int64_t(std::floor(hi.z)); ++z)
      for (int64_t y = int64_t(std::floor(lo.y)); y <= int64_t(std::floor(hi.y)); ++y)
        for (int64_t x = int64_t(std::floor(lo.x)); x <= int64_t(std::floor(hi.x)); ++x)
          visit(((z + 4096) << 26) ^ ((y + 4096) << 13) ^ (x + 4096));
  };
  size_t count = 0;
  auto one_way = [&](const TriMesh& e, const TriMesh& f) {
    std::unordered_map<int64_t, std::vector<uint32_t>> grid;
    for (size_t t = 0; t < f.triangle_count(); ++t)
      cells(f, t, [&](int64_t key) { grid[key].push_back(uint32_t(t)); });
    for (size_t s = 0; s < e.triangle_count(); ++s)
      cells(e, s, [&](int64_t key) {
        const auto it = grid.find(key);
        if (it == grid.end()) return;
        for (uint32_t t : it->second)
          for (int k = 0; k < 3; ++k)
            count += segment_crosses_triangle(corner(e, s, k), corner(e, s, (k + 1) % 3),
                                              corner(f, t, 0), corner(f, t, 1), corner(f, t, 2));
      });
  };
  one_way(m1, m2);
  one_way(m2, m1);
  return count;
}

}  // namespace segmesh::test
