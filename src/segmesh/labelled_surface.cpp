#include "segmesh/labelled_surface.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <span>
#include <utility>

#include "segmesh/smoothing.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

// A part's triangles: index into the surface, and whether the part is the outside (turned round).
struct PartTriangle {
  uint32_t triangle;
  bool turned;
};

// Per thread, per surface vertex: which part last used it (part + 1, 0: never) and its id in that
// part's shell, side by side (one cache line per corner looked up).
struct VertexStamp {
  uint32_t part, local;
};
using VertexStamps = std::vector<VertexStamp>;

// The two vertices of triangle t other than v, in the triangle's order.
std::pair<uint32_t, uint32_t> others_of(const TriMesh& shell, uint32_t t, uint32_t v) {
  const uint32_t* i = &shell.indices[3 * size_t{t}];
  const int c = i[0] == v ? 0 : i[1] == v ? 1 : 2;
  return {i[(c + 1) % 3], i[(c + 2) % 3]};
}

// An edge (v, w) of four shell triangles: two sheets of the shell meet along it (multi-label Dual
// Contouring contracts a junction cell's piece to one vertex; where a part reaches a cell face
// through two separate segments and the pieces on both sides hold both, the two sheets share the
// edge between the two pieces' vertices). Its triangles pair up by sheet: walking around v from
// one of them, over v's other edges, comes back to the edge through its partner (v's link is a
// figure eight through w; each loop is one sheet). Returns false where the walk meets another
// such edge first.
using SheetPairs = std::map<std::pair<uint32_t, uint32_t>, std::array<uint32_t, 4>>;

bool pair_by_sheet(const TriMesh& shell, uint32_t v, uint32_t w, std::span<const uint32_t> around_v,
                   const SheetPairs& known, std::array<uint32_t, 4>& edge) {
  auto degree = [&](uint32_t node) {
    int d = 0;
    for (uint32_t t : around_v) {
      const auto [a, b] = others_of(shell, t, v);
      d += (a == node) + (b == node);
    }
    return d;
  };
  uint32_t t = edge[0];
  uint32_t node = [&] {
    const auto [a, b] = others_of(shell, t, v);
    return a == w ? b : a;
  }();
  for (size_t step = 0; step <= around_v.size(); ++step) {
    uint32_t next = t;
    const int d = degree(node);
    if (d == 2) {
      for (uint32_t u : around_v) {
        if (u == t) continue;
        const auto [a, b] = others_of(shell, u, v);
        if (a == node || b == node) next = u;
      }
    } else {
      // Across another edge of four triangles already paired: on to t's partner there.
      const auto it = known.find({std::min(v, node), std::max(v, node)});
      if (d != 4 || it == known.end()) return false;
      const auto& pairs = it->second;
      const auto k = std::find(pairs.begin(), pairs.end(), t) - pairs.begin();
      if (k == 4) return false;
      next = pairs[size_t(k ^ 1)];
    }
    const auto [a, b] = others_of(shell, next, v);
    node = a == node ? b : a;
    t = next;
    if (node == w) {
      // edge[0] and t are one sheet: order the edge's triangles as two pairs.
      const auto at = std::find(edge.begin() + 1, edge.end(), t);
      if (at == edge.end()) return false;
      std::iter_swap(edge.begin() + 1, at);
      return true;
    }
  }
  return false;
}

// Gives a shell vertex that is shared by several fans of the shell's triangles (the shell touches
// itself there) one vertex per fan beyond the first, at the same position. Where two fans share an
// edge of four triangles (pair_by_sheet), the edge's triangles join by sheet only, so the fans part
// there too and the edge becomes two.
void split_pinches(TriMesh& shell, const std::vector<uint32_t>& candidates,
                   std::vector<uint32_t>* origin) {
  if (candidates.empty()) return;
  // The shell triangles at each candidate, as (vertex, triangle) pairs.
  std::vector<std::pair<uint32_t, uint32_t>> at;
  std::vector<char> is_candidate(shell.positions.size(), 0);
  for (uint32_t v : candidates) is_candidate[v] = 1;
  const size_t nt = shell.indices.size() / 3;
  for (uint32_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c)
      if (is_candidate[shell.indices[3 * t + c]]) at.push_back({shell.indices[3 * t + c], t});
  std::sort(at.begin(), at.end());
  std::vector<size_t> group_first;  // the triangles at each candidate: at[group_first[g] ..]
  for (size_t s = 0; s < at.size(); ++s)
    if (s == 0 || at[s].first != at[s - 1].first) group_first.push_back(s);
  group_first.push_back(at.size());
  // The edges (v, w) at a candidate with four shell triangles (where two sheets of the shell
  // share an edge; usually none), in candidate then neighbour order, each with its triangles.
  struct FourEdge {
    size_t group;
    uint32_t w;
    std::array<uint32_t, 4> triangles;
  };
  std::vector<FourEdge> fours;
  std::vector<std::pair<uint32_t, uint32_t>> by_neighbour;  // (w, triangle), sorted
  for (size_t g = 0; g + 1 < group_first.size(); ++g) {
    const uint32_t v = at[group_first[g]].first;
    by_neighbour.clear();
    for (size_t a = group_first[g]; a < group_first[g + 1]; ++a) {
      const uint32_t t = at[a].second;
      const auto [x, y] = others_of(shell, t, v);
      by_neighbour.push_back({x, t});
      by_neighbour.push_back({y, t});
    }
    std::sort(by_neighbour.begin(), by_neighbour.end());
    for (size_t i = 0, j; i < by_neighbour.size(); i = j) {
      for (j = i + 1; j < by_neighbour.size() && by_neighbour[j].first == by_neighbour[i].first;)
        ++j;
      if (j - i != 4) continue;
      fours.push_back({g, by_neighbour[i].first, {}});
      for (size_t k = 0; k < 4; ++k) fours.back().triangles[k] = by_neighbour[i + k].second;
    }
  }
  std::vector<uint32_t> around;
  // Their triangles paired by sheet (the first two and the last two), keyed by (lower vertex,
  // higher vertex). Passes until no edge is added: a walk may cross edges paired in an earlier
  // pass.
  SheetPairs sheets;
  for (bool added = !fours.empty(); added;) {
    added = false;
    for (const FourEdge& e : fours) {
      const uint32_t v = at[group_first[e.group]].first, w = e.w;
      const std::pair<uint32_t, uint32_t> key{std::min(v, w), std::max(v, w)};
      if (sheets.count(key)) continue;
      around.clear();
      for (size_t a = group_first[e.group]; a < group_first[e.group + 1]; ++a)
        around.push_back(at[a].second);
      std::array<uint32_t, 4> edge = e.triangles;
      if (pair_by_sheet(shell, v, w, around, sheets, edge)) {
        sheets[key] = edge;
        added = true;
      }
    }
  }
  std::vector<uint32_t> fan;
  std::vector<std::pair<uint32_t, uint32_t>> vertex_of_fan;
  for (size_t g = 0; g + 1 < group_first.size(); ++g) {
    const size_t s = group_first[g], e = group_first[g + 1];
    const uint32_t v = at[s].first;
    const size_t n = e - s;
    // Union-find over the triangles at v: two join when they share an edge (v, w), and on an edge
    // of four triangles paired by sheet only when they are one sheet.
    fan.resize(n);
    std::iota(fan.begin(), fan.end(), 0u);
    auto find = [&](uint32_t x) {
      while (fan[x] != x) x = fan[x] = fan[fan[x]];
      return x;
    };
    auto one_sheet = [&](uint32_t w, uint32_t ta, uint32_t tb) {
      const auto it = sheets.find({std::min(v, w), std::max(v, w)});
      if (it == sheets.end()) return true;
      const auto& edge = it->second;
      const auto pos = [&](uint32_t t) {
        return std::find(edge.begin(), edge.end(), t) - edge.begin();
      };
      return pos(ta) / 2 == pos(tb) / 2;
    };
    for (size_t a = 0; a < n; ++a) {
      const uint32_t ta = at[s + a].second;
      const auto [a1, a2] = others_of(shell, ta, v);
      for (size_t b = a + 1; b < n; ++b) {
        const uint32_t tb = at[s + b].second;
        const auto [b1, b2] = others_of(shell, tb, v);
        for (uint32_t w : {a1, a2})
          if ((w == b1 || w == b2) && one_sheet(w, ta, tb))
            fan[find(uint32_t(a))] = find(uint32_t(b));
      }
    }
    // Fans in the order of their first triangle; the first fan keeps v.
    vertex_of_fan.clear();  // (fan root, its vertex)
    for (size_t a = 0; a < n; ++a) {
      const uint32_t root = find(uint32_t(a));
      auto it = std::find_if(vertex_of_fan.begin(), vertex_of_fan.end(),
                             [&](const auto& f) { return f.first == root; });
      if (it == vertex_of_fan.end()) {
        uint32_t vertex = v;
        if (!vertex_of_fan.empty()) {
          vertex = static_cast<uint32_t>(shell.positions.size());
          shell.positions.push_back(shell.positions[v]);
          if (origin) origin->push_back((*origin)[v]);
        }
        vertex_of_fan.push_back({root, vertex});
        it = vertex_of_fan.end() - 1;
      }
      if (it->second == v) continue;
      uint32_t* i = &shell.indices[3 * at[s + a].second];
      for (int c = 0; c < 3; ++c)
        if (i[c] == v) i[c] = it->second;
    }
  }
}

}  // namespace

std::vector<TriMesh> part_shells(const LabelledSurface& surface, ShellOrigins* origin) {
  const size_t parts = surface.part_count;
  const size_t nt = surface.sides.size();
  // The triangles of each part: a counting sort by material.
  std::vector<size_t> first(parts + 2, 0);
  for (const auto& s : surface.sides) {
    for (uint32_t m : s)
      if (m != 0) ++first[m + 1];
  }
  for (size_t p = 1; p < first.size(); ++p) first[p] += first[p - 1];
  std::vector<PartTriangle> triangles(first.back());
  {
    std::vector<size_t> at(first.begin(), first.end() - 1);
    for (uint32_t t = 0; t < nt; ++t) {
      const auto& s = surface.sides[t];
      if (s[0] != 0) triangles[at[s[0]]++] = {t, false};
      if (s[1] != 0) triangles[at[s[1]]++] = {t, true};
    }
  }
  std::vector<char> junction(surface.mesh.positions.size(), 0);
  for (uint32_t v : surface.junction_vertices) junction[v] = 1;
  tbb::enumerable_thread_specific<VertexStamps> stamps([&] {
    return VertexStamps(surface.mesh.positions.size(), VertexStamp{0, 0});
  });
  std::vector<TriMesh> shells(parts);
  if (origin) origin->assign(parts, {});
  tbb::parallel_for(size_t{0}, parts, [&](size_t p) {
    std::vector<uint32_t>* from = origin ? &(*origin)[p] : nullptr;
    VertexStamps& stamp = stamps.local();
    const uint32_t material = static_cast<uint32_t>(p + 1);
    TriMesh& shell = shells[p];
    std::vector<uint32_t> candidates;
    const size_t count = first[material + 1] - first[material];
    shell.indices.resize(3 * count);
    // A closed shell has about half as many vertices as triangles.
    shell.positions.reserve(count / 2 + 64);
    if (from) from->reserve(count / 2 + 64);
    uint32_t* out = shell.indices.data();
    for (size_t q = first[material]; q < first[material + 1]; ++q) {
      const PartTriangle& pt = triangles[q];
      const uint32_t* i = &surface.mesh.indices[3 * size_t{pt.triangle}];
      const uint32_t corners[3] = {i[0], pt.turned ? i[2] : i[1], pt.turned ? i[1] : i[2]};
      for (uint32_t v : corners) {
        VertexStamp& st = stamp[v];
        if (st.part != material) {
          st = {material, static_cast<uint32_t>(shell.positions.size())};
          shell.positions.push_back(surface.mesh.positions[v]);
          if (from) from->push_back(v);
          if (junction[v]) candidates.push_back(st.local);
        }
        *out++ = st.local;
      }
    }
    split_pinches(shell, candidates, from);
    if (!surface.mesh.normals.empty()) compute_vertex_normals(shell);
  });
  return shells;
}

std::vector<PartContact> part_contacts(const LabelledSurface& surface) {
  std::map<std::pair<uint32_t, uint32_t>, double> area;
  const auto& p = surface.mesh.positions;
  for (size_t t = 0; t < surface.sides.size(); ++t) {
    const auto [in, out] = surface.sides[t];
    if (in == 0 || out == 0) continue;
    const uint32_t* i = &surface.mesh.indices[3 * t];
    const Vec3d a = to_double(p[i[0]]);
    area[{std::min(in, out), std::max(in, out)}] +=
        0.5 * norm(cross(to_double(p[i[1]]) - a, to_double(p[i[2]]) - a));
  }
  std::vector<PartContact> out;
  for (const auto& [pair, a] : area) out.push_back({pair.first, pair.second, a});
  return out;
}

}  // namespace segmesh
