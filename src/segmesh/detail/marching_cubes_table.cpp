#include "segmesh/detail/marching_cubes_table.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include "segmesh/quality.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

using Cycle = std::vector<int>;  // cut edges in order, counter-clockwise seen from outside

McCaseTopology case_topology(int cs, int connectivity);

int edge_between(int c0, int c1) {
  for (int e = 0; e < 12; ++e) {
    const auto& ec = kMcEdgeCorner[e];
    if ((ec[0] == c0 && ec[1] == c1) || (ec[0] == c1 && ec[1] == c0)) return e;
  }
  throw std::logic_error("marching cubes table: corners are not on one edge");
}

Vec3d corner_point(int c) {
  const auto& o = kMcCornerOffset[c];
  return {double(o[0]), double(o[1]), double(o[2])};
}

Vec3d edge_midpoint(int e) {
  return 0.5 * (corner_point(kMcEdgeCorner[e][0]) + corner_point(kMcEdgeCorner[e][1]));
}

// The six faces: axis a, side s. corners[] in cyclic order around the face.
struct Face {
  int axis = 0;
  int side = 0;
  std::array<int, 4> corners{};
  Vec3d outward;
};

std::array<Face, 6> make_faces() {
  std::array<Face, 6> faces;
  for (int a = 0; a < 3; ++a) {
    for (int s = 0; s < 2; ++s) {
      Face& f = faces[2 * a + s];
      f.axis = a;
      f.side = s;
      const int u = a == 0 ? 1 : 0;
      const int v = a == 2 ? 1 : 2;
      const std::array<std::array<int, 2>, 4> uv{{{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
      for (int q = 0; q < 4; ++q) {
        int c = s << a;
        c |= uv[q][0] << u;
        c |= uv[q][1] << v;
        f.corners[q] = c;
      }
      double n[3] = {0, 0, 0};
      n[a] = s ? 1.0 : -1.0;
      f.outward = {n[0], n[1], n[2]};
    }
  }
  return faces;
}

const std::array<Face, 6>& faces() {
  static const std::array<Face, 6> f = make_faces();
  return f;
}

bool share_face(int e0, int e1) { return mc_shared_face(e0, e1) >= 0; }


// Quality of a set of triangles: the worst radii ratio first, then the sum.
struct Score {
  double min = std::numeric_limits<double>::infinity();
  double sum = 0;
  bool valid = true;

  static Score invalid() { return {0, 0, false}; }
  Score plus(const Score& o) const {
    if (!valid || !o.valid) return invalid();
    return {std::min(min, o.min), sum + o.sum, true};
  }
  bool better_than(const Score& o) const {
    if (valid != o.valid) return valid;
    if (std::abs(min - o.min) > 1e-9) return min > o.min;
    return sum > o.sum + 1e-9;
  }
};

Score triangle_score(int e0, int e1, int e2) {
  const double r = radii_ratio(edge_midpoint(e0), edge_midpoint(e1), edge_midpoint(e2));
  return {r, r, true};
}

// Best triangulation of a cycle whose diagonals never join two vertices of one face (dynamic
// programming over sub-polygons, O(n^3) for n <= 12).
std::vector<std::array<uint8_t, 3>> triangulate_cycle(const Cycle& cycle) {
  const int n = static_cast<int>(cycle.size());
  if (n < 3) throw std::logic_error("marching cubes table: cycle shorter than 3");
  auto chord_ok = [&](int i, int j) {
    if (j - i == 1 || (i == 0 && j == n - 1)) return true;  // a side of the polygon
    return !share_face(cycle[i], cycle[j]);
  };
  std::vector<std::vector<Score>> best(n, std::vector<Score>(n, Score::invalid()));
  std::vector<std::vector<int>> split(n, std::vector<int>(n, -1));
  for (int i = 0; i + 1 < n; ++i) best[i][i + 1] = Score{};
  for (int len = 2; len < n; ++len) {
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      if (!chord_ok(i, j)) continue;
      for (int k = i + 1; k < j; ++k) {
        if (!chord_ok(i, k) || !chord_ok(k, j)) continue;
        const Score s = best[i][k].plus(best[k][j]).plus(
            triangle_score(cycle[i], cycle[k], cycle[j]));
        if (s.better_than(best[i][j])) {
          best[i][j] = s;
          split[i][j] = k;
        }
      }
    }
  }
  if (!best[0][n - 1].valid) {
    throw std::logic_error("marching cubes table: no face-safe triangulation of a cycle");
  }
  std::vector<std::array<uint8_t, 3>> triangles;
  std::vector<std::pair<int, int>> stack{{0, n - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int k = split[i][j];
    triangles.push_back({uint8_t(cycle[i]), uint8_t(cycle[k]), uint8_t(cycle[j])});
    stack.push_back({i, k});
    stack.push_back({k, j});
  }
  return triangles;
}

// A band of triangles joining two cycles into a tube. The cycles bound the tube from opposite
// ends, so walking forwards along `a` goes with walking backwards along `b`.
std::vector<std::array<uint8_t, 3>> tube_between(const Cycle& a, const Cycle& b) {
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  std::vector<std::array<uint8_t, 3>> best_tris;
  Score best = Score::invalid();
  const int moves = na + nb;
  for (int sa = 0; sa < na; ++sa) {
    for (int sb = 0; sb < nb; ++sb) {
      for (unsigned pattern = 0; pattern < (1u << moves); ++pattern) {
        if (std::popcount(pattern) != na) continue;  // bit set = advance along a
        std::vector<std::array<uint8_t, 3>> tris;
        Score score;
        int ia = sa, ib = sb;
        for (int m = 0; m < moves; ++m) {
          std::array<int, 3> t;
          if (pattern & (1u << m)) {
            t = {a[ia % na], a[(ia + 1) % na], b[((ib % nb) + nb) % nb]};
            ++ia;
          } else {
            t = {b[(((ib - 1) % nb) + nb) % nb], b[((ib % nb) + nb) % nb], a[ia % na]};
            --ib;
          }
          tris.push_back({uint8_t(t[0]), uint8_t(t[1]), uint8_t(t[2])});
          score = score.plus(triangle_score(t[0], t[1], t[2]));
        }
        if (score.better_than(best)) {
          best = score;
          best_tris = std::move(tris);
        }
      }
    }
  }
  return best_tris;
}

// Checks one case locally: every boundary segment is used once in its own direction, every other
// triangle edge exactly once in each direction.
void check_case(int cs, const std::map<std::pair<int, int>, int>& segments,
                const std::vector<std::array<uint8_t, 3>>& tris) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  }
  for (const auto& [edge, count] : directed) {
    const auto reverse = std::make_pair(edge.second, edge.first);
    const bool is_segment = segments.count(edge) > 0;
    const bool reverse_is_segment = segments.count(reverse) > 0;
    const int reverse_count = directed.count(reverse) ? directed.at(reverse) : 0;
    const bool ok = count == 1 && !reverse_is_segment &&
                    (is_segment ? reverse_count == 0 : reverse_count == 1);
    if (!ok) {
      throw std::logic_error("marching cubes table: inconsistent triangles in case " +
                             std::to_string(cs));
    }
  }
  for (const auto& [edge, unused] : segments) {
    if (!directed.count(edge)) {
      throw std::logic_error("marching cubes table: segment not covered in case " +
                             std::to_string(cs));
    }
  }
}

McCaseTopology case_topology(int cs, int connectivity) {
  const bool join_inside_on_faces = connectivity != 6;
  auto inside = [cs](int c) { return ((cs >> c) & 1) != 0; };

  // 1. Directed segments on the faces: from -> to, with the inside on the left of the direction
  //    as seen from outside the cell (cross(to - from, face normal) points into the inside).
  std::array<int, 12> next;
  next.fill(-1);
  for (int fi = 0; fi < 6; ++fi) {
    const Face& f = faces()[fi];
    std::array<int, 4> cut_edge;
    cut_edge.fill(-1);
    int cuts = 0;
    for (int q = 0; q < 4; ++q) {
      const int c0 = f.corners[q], c1 = f.corners[(q + 1) % 4];
      if (inside(c0) != inside(c1)) {
        cut_edge[q] = edge_between(c0, c1);
        ++cuts;
      }
    }
    // Pairs of cut edges, each with the corner it cuts off (or -1 when it halves the face).
    std::vector<std::array<int, 3>> pairs;
    if (cuts == 2) {
      std::array<int, 2> found{};
      int n = 0;
      for (int q = 0; q < 4; ++q) {
        if (cut_edge[q] >= 0) found[n++] = q;
      }
      int cut_off = -1;
      if (found[1] - found[0] == 1) cut_off = f.corners[found[1]];    // adjacent edges
      else if (found[0] == 0 && found[1] == 3) cut_off = f.corners[0];
      pairs.push_back({cut_edge[found[0]], cut_edge[found[1]], cut_off});
    } else if (cuts == 4) {
      for (int q = 0; q < 4; ++q) {
        const int c = f.corners[q];
        const bool separate_this = join_inside_on_faces ? !inside(c) : inside(c);
        if (separate_this) pairs.push_back({cut_edge[(q + 3) % 4], cut_edge[q], c});
      }
    }
    for (auto [e0, e1, cut_off] : pairs) {
      const Vec3d p0 = edge_midpoint(e0), p1 = edge_midpoint(e1);
      const Vec3d m = 0.5 * (p0 + p1);
      const Vec3d left = cross(p1 - p0, f.outward);
      int reference = cut_off;
      if (reference < 0) {
        for (int q = 0; q < 4; ++q) {
          if (inside(f.corners[q])) reference = f.corners[q];
        }
      }
      const double side = dot(left, corner_point(reference) - m);
      const bool reference_inside = inside(reference);
      if ((side > 0) != reference_inside) std::swap(e0, e1);
      if (next[e0] != -1) throw std::logic_error("marching cubes table: vertex with two exits");
      next[e0] = e1;
    }
  }

  // 2. Cycles.
  std::vector<Cycle> cycles;
  std::array<bool, 12> used{};
  for (int e = 0; e < 12; ++e) {
    if (next[e] < 0 || used[e]) continue;
    Cycle cycle;
    for (int v = e; !used[v]; v = next[v]) {
      if (next[v] < 0) throw std::logic_error("marching cubes table: open cycle");
      used[v] = true;
      cycle.push_back(v);
    }
    cycles.push_back(std::move(cycle));
  }

  const bool body_diagonal_pair =
      std::popcount(static_cast<unsigned>(cs)) == 2 && inside(std::countr_zero(unsigned(cs))) &&
      inside(std::countr_zero(unsigned(cs)) ^ 7);
  McCaseTopology topology{std::move(cycles), connectivity == 26 && body_diagonal_pair};
  if (topology.tube && topology.cycles.size() != 2) {
    throw std::logic_error("marching cubes table: tube needs two cycles");
  }
  return topology;
}

std::vector<std::array<uint8_t, 3>> build_case(int cs, int connectivity) {
  const McCaseTopology topology = case_topology(cs, connectivity);
  std::map<std::pair<int, int>, int> segments;  // (from edge, to edge) -> 1
  for (const Cycle& cycle : topology.cycles) {
    for (size_t i = 0; i < cycle.size(); ++i) segments[{cycle[i], cycle[(i + 1) % cycle.size()]}] = 1;
  }
  // A disk per cycle, or the tube that makes body-diagonal corners 26-connected.
  std::vector<std::array<uint8_t, 3>> tris;
  if (topology.tube) {
    tris = tube_between(topology.cycles[0], topology.cycles[1]);
  } else {
    for (const Cycle& cycle : topology.cycles) {
      auto t = triangulate_cycle(cycle);
      tris.insert(tris.end(), t.begin(), t.end());
    }
  }
  check_case(cs, segments, tris);
  return tris;
}

}  // namespace

int mc_shared_face(int e0, int e1) {
  if (e0 == e1) return -1;
  for (int fi = 0; fi < 6; ++fi) {
    const Face& f = faces()[fi];
    int found = 0;
    for (int q = 0; q < 4; ++q) {
      const int e = edge_between(f.corners[q], f.corners[(q + 1) % 4]);
      found += (e == e0) + (e == e1);
    }
    if (found == 2) return fi;
  }
  return -1;
}

McCaseTopology mc_case_topology(int cs, int connectivity) {
  require_connectivity(connectivity, "marching cubes");
  return case_topology(cs, connectivity);
}

McTable build_mc_table(int connectivity) {
  require_connectivity(connectivity, "marching cubes");
  McTable table;
  table.connectivity = connectivity;
  for (int cs = 0; cs < 256; ++cs) {
    table.first[cs] = static_cast<uint16_t>(table.triangles.size());
    const auto tris = build_case(cs, connectivity);
    table.triangles.insert(table.triangles.end(), tris.begin(), tris.end());
  }
  table.first[256] = static_cast<uint16_t>(table.triangles.size());
  return table;
}

const McTable& mc_table(int connectivity) {
  require_connectivity(connectivity, "marching cubes");
  static const McTable tables[3] = {build_mc_table(6), build_mc_table(18), build_mc_table(26)};
  return tables[connectivity_index(connectivity)];
}

}  // namespace segmesh
