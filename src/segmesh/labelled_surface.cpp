#include "segmesh/labelled_surface.hpp"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <numeric>
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

// Per thread: which part last used each surface vertex, and its id in that part's shell.
struct VertexStamps {
  std::vector<uint32_t> part;  // part + 1, 0: never
  std::vector<uint32_t> local;
};

// Gives a shell vertex that is shared by several fans of the shell's triangles (the shell touches
// itself there) one vertex per fan beyond the first, at the same position.
void split_pinches(TriMesh& shell, const std::vector<uint32_t>& candidates) {
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
  std::vector<uint32_t> fan;
  for (size_t s = 0; s < at.size();) {
    size_t e = s;
    while (e < at.size() && at[e].first == at[s].first) ++e;
    const uint32_t v = at[s].first;
    const size_t n = e - s;
    // Union-find over the triangles at v: two join when they share an edge (v, w).
    fan.resize(n);
    std::iota(fan.begin(), fan.end(), 0u);
    auto find = [&](uint32_t x) {
      while (fan[x] != x) x = fan[x] = fan[fan[x]];
      return x;
    };
    auto others = [&](uint32_t t) {
      const uint32_t* i = &shell.indices[3 * t];
      const int c = i[0] == v ? 0 : i[1] == v ? 1 : 2;
      return std::pair{i[(c + 1) % 3], i[(c + 2) % 3]};
    };
    for (size_t a = 0; a < n; ++a) {
      const auto [a1, a2] = others(at[s + a].second);
      for (size_t b = a + 1; b < n; ++b) {
        const auto [b1, b2] = others(at[s + b].second);
        if (a1 == b1 || a1 == b2 || a2 == b1 || a2 == b2) fan[find(uint32_t(a))] = find(uint32_t(b));
      }
    }
    // Fans by their first triangle; the first fan keeps v.
    std::map<uint32_t, uint32_t> vertex_of_fan;
    for (size_t a = 0; a < n; ++a) {
      const uint32_t root = find(uint32_t(a));
      auto [it, fresh] = vertex_of_fan.try_emplace(root, v);
      if (fresh && vertex_of_fan.size() > 1) {
        it->second = static_cast<uint32_t>(shell.positions.size());
        shell.positions.push_back(shell.positions[v]);
      }
      if (it->second == v) continue;
      uint32_t* i = &shell.indices[3 * at[s + a].second];
      for (int c = 0; c < 3; ++c)
        if (i[c] == v) i[c] = it->second;
    }
    s = e;
  }
}

}  // namespace

std::vector<TriMesh> part_shells(const LabelledSurface& surface) {
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
    return VertexStamps{std::vector<uint32_t>(surface.mesh.positions.size(), 0),
                        std::vector<uint32_t>(surface.mesh.positions.size(), 0)};
  });
  std::vector<TriMesh> shells(parts);
  tbb::parallel_for(size_t{0}, parts, [&](size_t p) {
    VertexStamps& stamp = stamps.local();
    const uint32_t material = static_cast<uint32_t>(p + 1);
    TriMesh& shell = shells[p];
    std::vector<uint32_t> candidates;
    const size_t count = first[material + 1] - first[material];
    shell.indices.reserve(3 * count);
    for (size_t q = first[material]; q < first[material + 1]; ++q) {
      const PartTriangle& pt = triangles[q];
      const uint32_t* i = &surface.mesh.indices[3 * size_t{pt.triangle}];
      const uint32_t corners[3] = {i[0], pt.turned ? i[2] : i[1], pt.turned ? i[1] : i[2]};
      for (uint32_t v : corners) {
        if (stamp.part[v] != material) {
          stamp.part[v] = material;
          stamp.local[v] = static_cast<uint32_t>(shell.positions.size());
          shell.positions.push_back(surface.mesh.positions[v]);
          if (junction[v]) candidates.push_back(stamp.local[v]);
        }
        shell.indices.push_back(stamp.local[v]);
      }
    }
    split_pinches(shell, candidates);
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
