// An independent, deliberately simple connected-component labelling (breadth-first search over
// voxels) that tests compare the library's run-based union-find and Marching Cubes topology with.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <queue>
#include <set>
#include <utility>
#include <vector>

#include "segmesh/volume.hpp"

namespace segmesh::test {

// Component id per voxel (-1 where same(v) is false) of the voxels for which `member(value)` holds;
// two member voxels join when they are `connectivity`-neighbours (6, 18, 26) and `same(a, b)`.
template <class T, class Member, class Same>
std::vector<int> reference_components(const Volume<T>& v, int connectivity, Member member,
                                      Same same, int& count) {
  const auto& d = v.grid.dims;
  std::vector<int> comp(v.voxels.size(), -1);
  count = 0;
  for (size_t start = 0; start < v.voxels.size(); ++start) {
    if (!member(v.voxels[start]) || comp[start] >= 0) continue;
    std::queue<size_t> q;
    q.push(start);
    comp[start] = count;
    while (!q.empty()) {
      const size_t at = q.front();
      q.pop();
      const int64_t i = at % d[0], j = (at / d[0]) % d[1], k = at / (d[0] * d[1]);
      for (int dk = -1; dk <= 1; ++dk)
        for (int dj = -1; dj <= 1; ++dj)
          for (int di = -1; di <= 1; ++di) {
            const int order = std::abs(di) + std::abs(dj) + std::abs(dk);
            if (order == 0 || (connectivity == 6 && order > 1) ||
                (connectivity == 18 && order > 2))
              continue;
            const int64_t a = i + di, b = j + dj, c = k + dk;
            if (a < 0 || b < 0 || c < 0 || a >= d[0] || b >= d[1] || c >= d[2]) continue;
            const size_t n = v.grid.index(a, b, c);
            if (comp[n] < 0 && member(v.voxels[n]) && same(v.voxels[at], v.voxels[n])) {
              comp[n] = count;
              q.push(n);
            }
          }
    }
    ++count;
  }
  return comp;
}

// Components of each non-zero label (voxels join when they carry the same label).
template <class T>
std::vector<int> reference_label_components(const Volume<T>& v, int connectivity, int& count) {
  return reference_components(
      v, connectivity, [](T x) { return x != 0; }, [](T a, T b) { return a == b; }, count);
}

// The surfaces Marching Cubes and Dual Contouring make of a padded 0/1 volume: the foreground
// under `connectivity` and the background under the connectivity our case table pairs with it.
// Connected components of voxels with value == `want` under 6/18/26-connectivity.
inline std::vector<int> label_components(const Volume<uint8_t>& v, uint8_t want, int connectivity,
                                  int& count) {
  return reference_components(
      v, connectivity, [want](uint8_t x) { return x == want; },
      [](uint8_t, uint8_t) { return true; }, count);
}

// The background connectivity that pairs with each foreground connectivity in our table.
inline int paired_background(int connectivity) { return connectivity == 6 ? 18 : 6; }

// In a well-composed pairing every (foreground component, background component) pair that touches
// is separated by exactly one connected surface.
inline int64_t expected_shells(const Volume<uint8_t>& v, int connectivity) {
  int nf = 0, nb = 0;
  const auto fg = label_components(v, 1, connectivity, nf);
  const auto bg = label_components(v, 0, paired_background(connectivity), nb);
  std::set<std::pair<int, int>> pairs;
  const auto& d = v.grid.dims;
  for (int64_t k = 0; k < d[2]; ++k)
    for (int64_t j = 0; j < d[1]; ++j)
      for (int64_t i = 0; i < d[0]; ++i) {
        const size_t a = v.grid.index(i, j, k);
        for (int axis = 0; axis < 3; ++axis) {
          const int64_t i1 = i + (axis == 0), j1 = j + (axis == 1), k1 = k + (axis == 2);
          if (i1 >= d[0] || j1 >= d[1] || k1 >= d[2]) continue;
          const size_t b = v.grid.index(i1, j1, k1);
          if (v.voxels[a] == v.voxels[b]) continue;
          pairs.insert(v.voxels[a] ? std::make_pair(fg[a], bg[b]) : std::make_pair(fg[b], bg[a]));
        }
      }
  return static_cast<int64_t>(pairs.size());
}

}  // namespace segmesh::test
