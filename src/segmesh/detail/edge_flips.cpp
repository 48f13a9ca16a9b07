#include "segmesh/detail/edge_flips.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_set>
#include <vector>

#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

uint64_t edge_key(uint32_t a, uint32_t b) {
  return uint64_t{std::min(a, b)} << 32 | std::max(a, b);
}

struct EdgeUse {
  uint64_t key;
  uint32_t triangle;
  bool operator<(const EdgeUse& o) const {
    return key != o.key ? key < o.key : triangle < o.triangle;
  }
};

constexpr double kMaxNormalTurnCos = 0.5;  // 60 degrees

}  // namespace

int64_t improve_by_edge_flips(LabelledSurface& s, double tolerance_mm) {
  if (!(tolerance_mm > 0)) return 0;
  std::vector<uint32_t>& idx = s.mesh.indices;
  auto at = [&](uint32_t v) { return to_double(s.mesh.positions[v]); };
  const size_t nt = s.sides.size();
  int64_t flips = 0;
  for (int pass = 0; pass < kEdgeFlipPasses; ++pass) {
    std::vector<EdgeUse> uses;
    uses.reserve(3 * nt);
    std::unordered_set<uint64_t> edges;
    edges.reserve(2 * nt);
    for (uint32_t t = 0; t < nt; ++t)
      for (int c = 0; c < 3; ++c) {
        const uint64_t k = edge_key(idx[3 * t + c], idx[3 * t + (c + 1) % 3]);
        uses.push_back({k, t});
        edges.insert(k);
      }
    std::sort(uses.begin(), uses.end());
    std::vector<char> changed(nt, 0);
    int64_t flipped = 0;
    for (size_t i = 0; i < uses.size();) {
      size_t j = i;
      while (j < uses.size() && uses[j].key == uses[i].key) ++j;
      const size_t n = j - i;
      const uint32_t t1 = uses[i].triangle, t2 = n == 2 ? uses[i + 1].triangle : 0;
      const size_t first = i;
      i = j;
      if (n != 2 || changed[t1] || changed[t2]) continue;
      // The same interface wound the same way, or the other way ((1, 2) beside (2, 1)).
      if (!same_interface(s.sides[t1], s.sides[t2])) continue;
      const bool turned = s.sides[t1] != s.sides[t2];
      // t1 = (a, b, c) with the edge a -> b; t2 holds b -> a (a -> b when turned).
      const uint32_t a0 = uint32_t(uses[first].key >> 32), b0 = uint32_t(uses[first].key);
      int r = 0;
      while (!((idx[3 * t1 + r] == a0 || idx[3 * t1 + r] == b0) &&
               (idx[3 * t1 + (r + 1) % 3] == a0 || idx[3 * t1 + (r + 1) % 3] == b0)))
        ++r;
      const uint32_t a = idx[3 * t1 + r], b = idx[3 * t1 + (r + 1) % 3],
                     c = idx[3 * t1 + (r + 2) % 3];
      const uint32_t from = turned ? a : b, to = turned ? b : a;
      int q = 0;
      while (q < 3 && !(idx[3 * t2 + q] == from && idx[3 * t2 + (q + 1) % 3] == to)) ++q;
      if (q == 3) continue;
      const uint32_t d = idx[3 * t2 + (q + 2) % 3];
      if (c == d || edges.count(edge_key(c, d))) continue;
      const Vec3d pa = at(a), pb = at(b), pc = at(c), pd = at(d);
      const double before = std::min(radii_ratio(pa, pb, pc), radii_ratio(pb, pa, pd));
      const double after = std::min(radii_ratio(pa, pd, pc), radii_ratio(pd, pb, pc));
      if (!(after > before + 1e-9)) continue;
      // Normals as seen from t1's side.
      const Vec3d n0 = cross(pb - pa, pc - pa) + cross(pa - pb, pd - pb);
      const Vec3d n1 = cross(pd - pa, pc - pa), n2 = cross(pb - pd, pc - pd);
      if (dot(n0, n1) < kMaxNormalTurnCos * norm(n0) * norm(n1) ||
          dot(n0, n2) < kMaxNormalTurnCos * norm(n0) * norm(n2))
        continue;
      const Vec3d lines = cross(pb - pa, pd - pc);
      const double height = std::abs(dot(lines, pc - pa)) / std::max(norm(lines), 1e-30);
      if (height > tolerance_mm) continue;
      // (a, d, c) and (d, b, c): the quad a -> d -> b -> c keeps its winding (t2 turned back
      // when its sides are the other way round).
      idx[3 * t1] = a, idx[3 * t1 + 1] = d, idx[3 * t1 + 2] = c;
      if (turned) {
        idx[3 * t2] = c, idx[3 * t2 + 1] = b, idx[3 * t2 + 2] = d;
      } else {
        idx[3 * t2] = d, idx[3 * t2 + 1] = b, idx[3 * t2 + 2] = c;
      }
      edges.erase(edge_key(a, b));
      edges.insert(edge_key(c, d));
      changed[t1] = changed[t2] = 1;
      ++flipped;
    }
    flips += flipped;
    if (flipped == 0) break;
  }
  return flips;
}

}  // namespace segmesh
