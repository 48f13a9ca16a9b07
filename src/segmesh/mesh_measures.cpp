#include "segmesh/mesh_measures.hpp"

#include <algorithm>
#include <numeric>
#include <vector>

namespace segmesh {

namespace {

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

}  // namespace

MeshMeasures measure_mesh(const TriMesh& mesh) {
  MeshMeasures m;
  const size_t nv = mesh.positions.size();
  const size_t nt = mesh.triangle_count();
  m.triangles = static_cast<int64_t>(nt);
  if (nt == 0) return m;
  const auto& idx = mesh.indices;

  // Area and volume, relative to the centroid of the vertices to keep the sums well conditioned
  // far from the world origin.
  Vec3d centre{};
  for (const Vec3f& p : mesh.positions) centre = centre + to_double(p);
  centre = (1.0 / double(nv)) * centre;
  double area = 0, volume6 = 0;
  for (size_t t = 0; t < nt; ++t) {
    const Vec3d a = to_double(mesh.positions[idx[3 * t]]) - centre;
    const Vec3d b = to_double(mesh.positions[idx[3 * t + 1]]) - centre;
    const Vec3d c = to_double(mesh.positions[idx[3 * t + 2]]) - centre;
    const Vec3d n = cross(b - a, c - a);
    const double twice_area = norm(n);
    area += twice_area;
    volume6 += dot(a, cross(b, c));
    if (twice_area == 0) ++m.degenerate_triangles;
  }
  m.area_mm2 = 0.5 * area;
  m.volume_mm3 = volume6 / 6.0;

  // Outgoing half-edges per vertex, compressed rows.
  std::vector<uint32_t> first(nv + 1, 0);
  for (size_t h = 0; h < idx.size(); ++h) ++first[idx[h] + 1];
  std::partial_sum(first.begin(), first.end(), first.begin());
  std::vector<uint32_t> to(idx.size());
  {
    std::vector<uint32_t> fill(first.begin(), first.end() - 1);
    for (size_t t = 0; t < nt; ++t) {
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = idx[3 * t + k], b = idx[3 * t + (k + 1) % 3];
        to[fill[a]++] = b;
      }
    }
  }
  for (size_t v = 0; v < nv; ++v) std::sort(to.begin() + first[v], to.begin() + first[v + 1]);
  auto count_half_edges = [&](uint32_t a, uint32_t b) {
    const auto lo = to.begin() + first[a], hi = to.begin() + first[a + 1];
    return static_cast<int64_t>(std::upper_bound(lo, hi, b) - std::lower_bound(lo, hi, b));
  };

  // Each undirected edge {a, b} is looked at once: from its smaller end, or from the larger end
  // when no half-edge leaves the smaller one.
  for (uint32_t a = 0; a < nv; ++a) {
    for (uint32_t h = first[a]; h < first[a + 1]; ++h) {
      const uint32_t b = to[h];
      if (h > first[a] && to[h - 1] == b) continue;  // repeated half-edge, already counted
      const int64_t ab = count_half_edges(a, b);
      const int64_t ba = count_half_edges(b, a);
      if (a > b && ba > 0) continue;  // counted from b
      ++m.edges;
      const int64_t uses = ab + ba;
      if (uses == 1) ++m.boundary_edges;
      else if (uses > 2) ++m.nonmanifold_edges;
      else if (ab != 1) ++m.winding_errors;
    }
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
  m.euler = m.vertices - m.edges + m.triangles;
  return m;
}

}  // namespace segmesh
