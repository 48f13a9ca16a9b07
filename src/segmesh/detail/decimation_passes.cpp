#include "segmesh/detail/decimation_passes.hpp"

#include <algorithm>
#include <cmath>

#include "segmesh/labelled_surface.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {
constexpr double kRelaxTurnCos = 0.8660254037844387;  // 30 degrees
// Relaxation takes a move that makes the mean radii ratio around the vertex better if the worst
// stays at least this (or where it was), besides any move that makes the worst better.
constexpr double kRelaxKeepWorst = 0.3;
}  // namespace

int64_t flip_pass(DecimationMesh& m, double tolerance, double limit2) {
  if (!(tolerance > 0)) return 0;
  int64_t flipped = 0;
  for (uint32_t t1 = 0; t1 < m.alive_tri.size(); ++t1) {
    for (int r = 0; r < 3 && m.alive_tri[t1]; ++r) {
      uint32_t* i1 = &m.s.mesh.indices[3 * size_t(t1)];
      const uint32_t a = i1[r], b = i1[(r + 1) % 3], c = i1[(r + 2) % 3];
      uint32_t t2 = ~0u;
      int on_edge = 0;
      m.for_edge_triangles(a, b, [&](uint32_t t) {
        ++on_edge;
        if (t != t1) t2 = t;
      });
      if (on_edge != 2 || t2 == ~0u || !same_interface(m.s.sides[t1], m.s.sides[t2])) continue;
      // t2 holds b -> a, or a -> b when its sides are the other way round.
      const bool turned = m.s.sides[t1] != m.s.sides[t2];
      const uint32_t from = turned ? a : b, to = turned ? b : a;
      uint32_t* i2 = &m.s.mesh.indices[3 * size_t(t2)];
      int q = 0;
      while (q < 3 && !(i2[q] == from && i2[(q + 1) % 3] == to)) ++q;
      if (q == 3) continue;
      const uint32_t d = i2[(q + 2) % 3];
      if (c == d) continue;
      {
        const ListPool::Lease around_c = m.neighbours(c);
        if (std::binary_search(around_c->begin(), around_c->end(), d)) continue;
      }
      const Vec3d pa = m.pos[a], pb = m.pos[b], pc = m.pos[c], pd = m.pos[d];
      const double before = std::min(radii_ratio(pa, pb, pc), radii_ratio(pb, pa, pd));
      const double after = std::min(radii_ratio(pa, pd, pc), radii_ratio(pd, pb, pc));
      if (!(after > before + 1e-9)) continue;
      // Normals as seen from t1's side.
      const Vec3d n0 = cross(pb - pa, pc - pa) + cross(pa - pb, pd - pb);
      const Vec3d n1 = cross(pd - pa, pc - pa), n2 = cross(pb - pd, pc - pd);
      if (dot(n0, n1) < kDecimationMaxTurnCos * norm(n0) * norm(n1) ||
          dot(n0, n2) < kDecimationMaxTurnCos * norm(n0) * norm(n2))
        continue;
      const Vec3d lines = cross(pb - pa, pd - pc);
      const double height = std::abs(dot(lines, pc - pa)) / std::max(norm(lines), 1e-30);
      if (height > tolerance) continue;
      // (a, d, c) and (d, b, c): the quad a -> d -> b -> c keeps its winding (t2 turned back
      // when its sides are the other way round).
      const std::array<uint32_t, 3> new1{a, d, c};
      const std::array<uint32_t, 3> new2 = turned ? std::array<uint32_t, 3>{c, b, d}
                                                  : std::array<uint32_t, 3>{d, b, c};
      if (!m.flip_keeps_witnesses(t1, t2, new1, new2, {a, b, c, d}, limit2)) continue;
      m.commit_witnesses();
      std::copy(new1.begin(), new1.end(), i1);
      std::copy(new2.begin(), new2.end(), i2);
      std::erase(m.tris[a], t2);
      std::erase(m.tris[b], t1);
      m.tris[c].push_back(t2);
      m.tris[d].push_back(t1);
      ++flipped;
    }
  }
  return flipped;
}

int64_t relax_pass(DecimationMesh& m, double bound, double limit2) {
  int64_t moved = 0;
  {
    for (uint32_t v = 0; v < m.pos.size(); ++v) {
      if (!m.alive_vertex[v] || m.role[v] != SmoothRole::kSheet) continue;
      const ListPool::Lease ring = m.neighbours(v);
      if (ring->empty()) continue;
      Vec3d centroid{};
      bool all_sheet = true;
      for (uint32_t w : *ring) {
        all_sheet = all_sheet && m.role[w] == SmoothRole::kSheet;
        centroid = centroid + m.pos[w];
      }
      if (!all_sheet) continue;
      centroid = (1.0 / double(ring->size())) * centroid;
      Vec3d normal{};
      double worst_before = 1, sum_before = 0;
      for (uint32_t t : m.tris[v]) {
        if (!m.alive_tri[t]) continue;
        const uint32_t* i = &m.s.mesh.indices[3 * size_t(t)];
        normal = normal + cross(m.pos[i[1]] - m.pos[i[0]], m.pos[i[2]] - m.pos[i[0]]);
        const double r = m.rho(t);
        worst_before = std::min(worst_before, r);
        sum_before += r;
      }
      const double length = norm(normal);
      if (!(length > 0)) continue;
      normal = (1 / length) * normal;
      const Vec3d step = centroid - m.pos[v];
      const Vec3d p = m.pos[v] + (step - dot(step, normal) * normal);
      if (cost_mm(m.quadric[v], p) > std::max(bound, cost_mm(m.quadric[v], m.pos[v]))) continue;
      double worst_after = 1, sum_after = 0;
      bool turned = false;
      for (uint32_t t : m.tris[v]) {
        if (!m.alive_tri[t]) continue;
        const uint32_t* i = &m.s.mesh.indices[3 * size_t(t)];
        Vec3d q[3];
        for (int k = 0; k < 3; ++k) q[k] = i[k] == v ? p : m.pos[i[k]];
        const Vec3d n0 = cross(m.pos[i[1]] - m.pos[i[0]], m.pos[i[2]] - m.pos[i[0]]);
        const Vec3d n1 = cross(q[1] - q[0], q[2] - q[0]);
        const double l0 = norm(n0), l1 = norm(n1);
        if (!(l1 > 1e-12 * (l0 + 1e-30)) || dot(n0, n1) < kRelaxTurnCos * l0 * l1) {
          turned = true;
          break;
        }
        const double r = radii_ratio(q[0], q[1], q[2]);
        worst_after = std::min(worst_after, r);
        sum_after += r;
      }
      if (turned) continue;
      const bool better_worst = worst_after > worst_before;
      const bool better_mean = sum_after > sum_before + 1e-3 * double(ring->size()) &&
                               worst_after >= std::min(worst_before, kRelaxKeepWorst);
      if (!better_worst && !better_mean) continue;
      if (!m.collapse_keeps_witnesses(v, v, p, limit2)) continue;
      m.commit_witnesses();
      m.pos[v] = p;
      ++moved;
    }
  }
  return moved;
}

}  // namespace segmesh
