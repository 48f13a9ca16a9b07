#include "segmesh/mesh_measures.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "segmesh/detail/mesh_adjacency.hpp"

namespace segmesh {

namespace {

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

// A half-edge a -> b of a triangle (a, b, c), stored in a's row as b << 32 | c: rows sorted by
// these keys are sorted by b, and c is the triangle's corner before a (its other edge at a).
uint64_t half_edge_key(uint32_t to, uint32_t third) { return uint64_t{to} << 32 | third; }
uint32_t key_to(uint64_t key) { return static_cast<uint32_t>(key >> 32); }
uint32_t key_third(uint64_t key) { return static_cast<uint32_t>(key); }

// Sums over blocks of a fixed size, combined in a fixed tree: the same bits for any thread count.
template <class T, class F>
T deterministic_sum(size_t n, size_t grain, F&& body) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<size_t>(0, n, grain), T{},
      [&](const tbb::blocked_range<size_t>& r, T acc) { return acc + body(r.begin(), r.end()); },
      [](const T& a, const T& b) { return a + b; });
}

struct SurfaceSums {
  double area2 = 0, volume6 = 0;
  Vec3d normal_sum{};
  int64_t degenerate = 0;
  SurfaceSums operator+(const SurfaceSums& o) const {
    return {area2 + o.area2, volume6 + o.volume6, normal_sum + o.normal_sum,
            degenerate + o.degenerate};
  }
};

// Area and volume, relative to the centroid of the vertices to keep the sums well conditioned
// far from the world origin; the volume is moved back to the origin by the exact correction
// centroid . sum(n) (header comment), which is zero for a closed mesh.
void measure_surface(const std::vector<Vec3f>& pos, const std::vector<uint32_t>& idx,
                     MeshMeasures& m) {
  const size_t nv = pos.size(), nt = idx.size() / 3;
  const Vec3d centre = (1.0 / double(nv)) * deterministic_sum<Vec3d>(nv, 1 << 16, [&](size_t b, size_t e) {
    Vec3d s{};
    for (size_t v = b; v < e; ++v) s = s + to_double(pos[v]);
    return s;
  });
  const SurfaceSums sums = deterministic_sum<SurfaceSums>(nt, 1 << 15, [&](size_t b, size_t e) {
    SurfaceSums s;
    for (size_t t = b; t < e; ++t) {
      const Vec3d a = to_double(pos[idx[3 * t]]) - centre;
      const Vec3d bb = to_double(pos[idx[3 * t + 1]]) - centre;
      const Vec3d c = to_double(pos[idx[3 * t + 2]]) - centre;
      const Vec3d n = cross(bb - a, c - a);
      const double twice_area = norm(n);
      s.area2 += twice_area;
      s.volume6 += dot(a, cross(bb, c));
      s.normal_sum = s.normal_sum + n;
      if (twice_area == 0) ++s.degenerate;
    }
    return s;
  });
  m.degenerate_triangles = sums.degenerate;
  m.area_mm2 = 0.5 * sums.area2;
  m.volume_mm3 = (sums.volume6 + dot(centre, sums.normal_sum)) / 6.0;
}

// The topology of a mesh whose every vertex is the apex of one closed fan (mesh_adjacency.hpp,
// corners_to_rings): closed, edge-manifold and consistently wound by construction, so only the
// edge lengths, the used vertices and the shells are left to count. Each undirected edge {v, u}
// is seen from both ends and counted from the smaller one.
template <class Index>
void measure_rings(const TriMesh& mesh, const VertexRows<Index>& rings, MeshMeasures& m) {
  const auto& pos = mesh.positions;
  const size_t nv = pos.size();
  struct EdgeSums {
    double length = 0;
    int64_t edges = 0, used = 0;
    EdgeSums operator+(const EdgeSums& o) const {
      return {length + o.length, edges + o.edges, used + o.used};
    }
  };
  const EdgeSums sums = deterministic_sum<EdgeSums>(nv, 1 << 14, [&](size_t b, size_t e) {
    EdgeSums s;
    for (size_t v = b; v < e; ++v) {
      if (rings.size(v) > 0) ++s.used;
      for (const Index* u = rings.begin(v); u != rings.end(v); ++u) {
        if (*u < v) continue;
        ++s.edges;
        s.length += norm(to_double(pos[v]) - to_double(pos[*u]));
      }
    }
    return s;
  });
  m.vertices = sums.used;
  m.edges = sums.edges;
  m.mean_edge_length_mm = sums.length / double(sums.edges);
  // Shells: vertices joined through their edges; each fan's first neighbour and each ring step
  // join everything a triangle joins.
  std::vector<uint32_t> parent(nv);
  std::iota(parent.begin(), parent.end(), 0u);
  for (size_t v = 0; v < nv; ++v) {
    for (const Index* u = rings.begin(v); u != rings.end(v); ++u) {
      if (*u < v) continue;
      const uint32_t a = find_root(parent, static_cast<uint32_t>(v));
      const uint32_t b = find_root(parent, static_cast<uint32_t>(*u));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  for (size_t v = 0; v < nv; ++v)
    if (rings.size(v) > 0 && parent[v] == v) ++m.shells;
}

// Any mesh: half-edges counted one by one (header comment).
void measure_topology(const TriMesh& mesh, MeshMeasures& m) {
  const size_t nv = mesh.positions.size();
  const size_t nt = mesh.triangle_count();
  const auto& idx = mesh.indices;
  const auto& pos = mesh.positions;
  // Outgoing half-edges per vertex, compressed rows, each with its triangle's third corner.
  std::vector<uint32_t> first(nv + 1, 0);
  for (size_t h = 0; h < idx.size(); ++h) ++first[idx[h] + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<uint64_t> half(idx.size());
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (size_t t = 0; t < nt; ++t) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = idx[3 * t + k], b = idx[3 * t + (k + 1) % 3];
        const uint32_t c = idx[3 * t + (k + 2) % 3];
        half[fill[a]++] = half_edge_key(b, c);
      }
    }
  }
  for (size_t v = 0; v < nv; ++v) std::sort(half.begin() + first[v], half.begin() + first[v + 1]);
  auto count_half_edges = [&](uint32_t a, uint32_t b) {
    const auto lo = half.begin() + first[a], hi = half.begin() + first[a + 1];
    return static_cast<int64_t>(std::upper_bound(lo, hi, half_edge_key(b, UINT32_MAX)) -
                                std::lower_bound(lo, hi, half_edge_key(b, 0)));
  };

  // Each undirected edge {a, b} is looked at once: from its smaller end, or from the larger end
  // when no half-edge leaves the smaller one. An edge from a vertex to itself (a triangle that
  // repeats an index) is one edge used once per half-edge, as mesh_metrics.py counts it.
  double length_sum = 0;
  for (uint32_t a = 0; a < nv; ++a) {
    for (uint32_t h = first[a]; h < first[a + 1]; ++h) {
      const uint32_t b = key_to(half[h]);
      if (h > first[a] && key_to(half[h - 1]) == b) continue;  // a repeat, already counted
      const int64_t ab = count_half_edges(a, b);
      const int64_t ba = a == b ? 0 : count_half_edges(b, a);
      if (a > b && ba > 0) continue;  // counted from b
      ++m.edges;
      length_sum += norm(to_double(pos[a]) - to_double(pos[b]));
      const int64_t uses = ab + ba;
      if (uses == 1) ++m.boundary_edges;
      else if (uses > 2) ++m.nonmanifold_edges;
      else if (ab != 1) ++m.winding_errors;
    }
  }
  m.mean_edge_length_mm = length_sum / double(m.edges);

  // Fans: around vertex v, each edge {v, u} is a node named by u, and each triangle corner at v
  // links its two edges (u = the half-edge's end, and the third corner). The fans are the
  // connected groups of nodes. An edge {v, v} has a second end that no corner reaches, so it is
  // a group of its own, as in mesh_metrics.py's (edge, end) nodes.
  std::vector<uint32_t> ends, group;
  for (uint32_t v = 0; v < nv; ++v) {
    if (first[v] == first[v + 1]) continue;
    ends.clear();
    bool self_edge = false;
    for (uint32_t h = first[v]; h < first[v + 1]; ++h) {
      ends.push_back(key_to(half[h]));
      ends.push_back(key_third(half[h]));
      self_edge = self_edge || key_to(half[h]) == v;
    }
    std::sort(ends.begin(), ends.end());
    ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
    group.resize(ends.size());
    std::iota(group.begin(), group.end(), 0u);
    auto node = [&](uint32_t u) {
      return static_cast<uint32_t>(std::lower_bound(ends.begin(), ends.end(), u) - ends.begin());
    };
    size_t fans = ends.size() + (self_edge ? 1 : 0);
    for (uint32_t h = first[v]; h < first[v + 1]; ++h) {
      const uint32_t x = find_root(group, node(key_to(half[h])));
      const uint32_t y = find_root(group, node(key_third(half[h])));
      if (x != y) {
        group[y] = x;
        --fans;
      }
    }
    if (fans > 1) ++m.nonmanifold_vertices;
  }

  // Shells: triangles connected through shared vertices.
  std::vector<uint32_t> parent(nv);
  std::iota(parent.begin(), parent.end(), 0u);
  std::vector<bool> used(nv, false);
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t a = find_root(parent, idx[3 * t]);
    for (int k = 0; k < 3; ++k) used[idx[3 * t + k]] = true;
    for (int k = 1; k < 3; ++k) {
      const uint32_t b = find_root(parent, idx[3 * t + k]);
      if (a != b) parent[b] = a;
    }
  }
  for (uint32_t v = 0; v < nv; ++v) {
    if (!used[v]) continue;
    ++m.vertices;
    if (find_root(parent, v) == v) ++m.shells;
  }
}

}  // namespace

MeshMeasures measure_mesh(const TriMesh& mesh) {
  MeshMeasures m;
  const size_t nt = mesh.triangle_count();
  m.triangles = static_cast<int64_t>(nt);
  if (nt == 0) return m;
  measure_surface(mesh.positions, mesh.indices, m);
  // Meshing output (closed oriented manifolds) takes the parallel path; anything else, or a
  // mesh too large for 32-bit rows, the general one.
  bool rings = false;
  if (mesh_rows_fit_32(mesh.indices.size())) {
    VertexRows<uint32_t> rows = vertex_corners<uint32_t>(mesh.indices, mesh.positions.size());
    rings = corners_to_rings(mesh.indices, rows);
    if (rings) measure_rings(mesh, rows, m);
  }
  if (!rings) measure_topology(mesh, m);
  m.euler = m.vertices - m.edges + m.triangles;
  return m;
}

double enclosed_volume(const TriMesh& mesh) {
  return enclosed_volume(mesh.positions, mesh.indices);
}

double surface_area(const TriMesh& mesh) {
  MeshMeasures m;
  if (mesh.indices.size() >= 3) measure_surface(mesh.positions, mesh.indices, m);
  return m.area_mm2;
}

double enclosed_volume(const std::vector<Vec3f>& positions, const std::vector<uint32_t>& indices) {
  MeshMeasures m;
  if (indices.size() >= 3) measure_surface(positions, indices, m);
  return m.volume_mm3;
}

}  // namespace segmesh
