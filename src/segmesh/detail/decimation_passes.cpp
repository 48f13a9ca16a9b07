#include "segmesh/detail/decimation_passes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "segmesh/labelled_surface.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {
constexpr double kRelaxTurnCos = 0.8660254037844387;  // 30 degrees
// Relaxation takes a move that makes the mean radii ratio around the vertex better if the worst
// stays at least this (or where it was), besides any move that makes the worst better.
constexpr double kRelaxKeepWorst = 0.3;

// The quad across edge (a, b) of live triangle t1 (a -> b in t1's winding): the other triangle
// on it, of the same interface, and its corner d off the edge; nullopt when the edge has another
// number of triangles (a junction curve's edge), another interface, or d is t1's third corner.
struct Quad {
  uint32_t t2, d;
  bool turned;  // t2's sides are t1's the other way round (it holds a -> b)
};
std::optional<Quad> quad_across(const DecimationMesh& m, uint32_t t1, uint32_t a, uint32_t b, uint32_t c) {
  uint32_t t2 = ~0u;
  int on_edge = 0;
  m.for_edge_triangles(a, b, [&](uint32_t t) {
    ++on_edge;
    if (t != t1) t2 = t;
  });
  if (on_edge != 2 || t2 == ~0u || !same_interface(m.s.sides[t1], m.s.sides[t2])) return std::nullopt;
  // t2 holds b -> a, or a -> b when its sides are the other way round.
  const bool turned = m.s.sides[t1] != m.s.sides[t2];
  const uint32_t from = turned ? a : b, to = turned ? b : a;
  const uint32_t* i2 = &m.s.mesh.indices[3 * size_t(t2)];
  int q = 0;
  while (q < 3 && !(i2[q] == from && i2[(q + 1) % 3] == to)) ++q;
  if (q == 3) return std::nullopt;
  const uint32_t d = i2[(q + 2) % 3];
  if (c == d) return std::nullopt;
  return Quad{t2, d, turned};
}

// The quad a -> d -> b -> c's two triangles after the flip of (a, b) into (c, d), keeping its
// winding (t2 turned back when its sides are the other way round).
std::array<std::array<uint32_t, 3>, 2> flip_triangles(uint32_t a, uint32_t b, uint32_t c, const Quad& q) {
  return {std::array<uint32_t, 3>{a, q.d, c},
          q.turned ? std::array<uint32_t, 3>{c, b, q.d} : std::array<uint32_t, 3>{q.d, b, c}};
}

// Replaces t1 and t2 by the flipped pair (the witnesses already committed).
void apply_flip(DecimationMesh& m, uint32_t t1, uint32_t a, uint32_t b, uint32_t c, const Quad& q) {
  const auto [new1, new2] = flip_triangles(a, b, c, q);
  std::copy(new1.begin(), new1.end(), &m.s.mesh.indices[3 * size_t(t1)]);
  std::copy(new2.begin(), new2.end(), &m.s.mesh.indices[3 * size_t(q.t2)]);
  m.tris.erase(a, q.t2);
  m.tris.erase(b, t1);
  m.tris.push_back(c, q.t2);
  m.tris.push_back(q.d, t1);
}

bool are_neighbours(const DecimationMesh& m, uint32_t c, uint32_t d) {
  const ListPool::Lease around_c = m.neighbours(c);
  return std::binary_search(around_c->begin(), around_c->end(), d);
}

// Whether a flip keeps the original surface near it: every sample of an original triangle near
// the quad (its corners, its edges' midpoints and its centroid) within sqrt(limit2) of the quad's
// two triangles stays that near to the flipped pair or to another live triangle at a corner of the
// quad. A flip moves the surface off the old pair by up to the height between the diagonals,
// and the witnesses see only the original vertices: without this, flips of slivers that used the
// whole bound left points inside original triangles beyond it (0.206 mm for 0.2 on the test
// plate). Checked only for flips that move the surface more than the passes' own tolerance.
bool flip_keeps_original_near(const DecimationMesh& m, uint32_t t1, uint32_t t2,
                              const std::array<uint32_t, 4>& corners,
                              const std::array<std::array<uint32_t, 3>, 2>& flipped,
                              double limit2) {
  if (!m.original) return true;
  const DecimationMesh::Original& o = *m.original;
  auto triangle = [&](const uint32_t* i) {
    return std::array<Vec3d, 3>{m.pos[i[0]], m.pos[i[1]], m.pos[i[2]]};
  };
  const std::array<std::array<Vec3d, 3>, 2> before{triangle(&m.s.mesh.indices[3 * size_t(t1)]),
                                                   triangle(&m.s.mesh.indices[3 * size_t(t2)])};
  const std::array<std::array<Vec3d, 3>, 2> after{triangle(flipped[0].data()),
                                                  triangle(flipped[1].data())};
  auto near = [&](const Vec3d& q, const auto& triangles) {
    for (const auto& x : triangles)
      if (point_triangle_distance2(q, x[0], x[1], x[2]) <= limit2) return true;
    return false;
  };
  thread_local std::vector<uint32_t> found;
  thread_local std::vector<std::array<Vec3d, 3>> around;
  found.clear();
  around.clear();
  const double r = std::sqrt(limit2);
  Vec3d lo = m.pos[corners[0]], hi = lo;
  for (uint32_t x : corners) {
    lo = {std::min(lo.x, m.pos[x].x), std::min(lo.y, m.pos[x].y), std::min(lo.z, m.pos[x].z)};
    hi = {std::max(hi.x, m.pos[x].x), std::max(hi.y, m.pos[x].y), std::max(hi.z, m.pos[x].z)};
  }
  o.tree->overlapping(lo - Vec3d{r, r, r}, hi + Vec3d{r, r, r}, found);
  bool around_made = false;
  for (uint32_t t : found) {
    const Vec3d a = to_double(o.positions[o.indices[3 * size_t(t)]]);
    const Vec3d b = to_double(o.positions[o.indices[3 * size_t(t) + 1]]);
    const Vec3d c = to_double(o.positions[o.indices[3 * size_t(t) + 2]]);
    const Vec3d samples[7] = {
        a, b, c, 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a), (1.0 / 3.0) * (a + b + c)};
    for (const Vec3d& q : samples) {
      if (!near(q, before) || near(q, after)) continue;
      if (!around_made) {  // the quad's neighbours, made once for the first sample that needs them
        for (uint32_t x : corners)
          for (uint32_t u : m.tris[x])
            if (m.alive_tri[u] && u != t1 && u != t2)
              around.push_back(triangle(&m.s.mesh.indices[3 * size_t(u)]));
        around_made = true;
      }
      if (!near(q, around)) return false;
    }
  }
  return true;
}

}  // namespace

int64_t flip_pass(DecimationMesh& m, double tolerance, double bound, double limit2) {
  if (!(tolerance > 0)) return 0;
  int64_t flipped = 0;
  for (uint32_t t1 = 0; t1 < m.alive_tri.size(); ++t1) {
    for (int r = 0; r < 3 && m.alive_tri[t1]; ++r) {
      const uint32_t* i1 = &m.s.mesh.indices[3 * size_t(t1)];
      const uint32_t a = i1[r], b = i1[(r + 1) % 3], c = i1[(r + 2) % 3];
      const std::optional<Quad> quad = quad_across(m, t1, a, b, c);
      if (!quad || are_neighbours(m, c, quad->d)) continue;
      const uint32_t d = quad->d;
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
      // A flip that removes a sliver may move the surface by the whole bound where an original
      // surface is kept (an error bound), since the points it makes and the original surface
      // near it are then checked both ways below; with a budget alone, by what the bound leaves
      // above the quad's corners' own errors (their quadrics), when that is more than
      // `tolerance`.
      double allowed = tolerance;
      if (before < kDecimationSliverRho && height > tolerance) {
        if (m.original) {
          allowed = bound;
        } else {
          double local = 0;
          for (uint32_t x : {a, b, c, d}) local = std::max(local, cost_mm(m.quadric[x], m.pos[x]));
          allowed = std::max(tolerance, bound - local);
        }
      }
      if (height > allowed) continue;
      // The points the flip makes: the new triangles' centroids and the new edge's midpoint.
      if (!m.near_original((1.0 / 3.0) * (pa + pd + pc), limit2, c) ||
          !m.near_original((1.0 / 3.0) * (pd + pb + pc), limit2, d) ||
          !m.near_original(0.5 * (pc + pd), limit2, c))
        continue;
      const auto pair = flip_triangles(a, b, c, *quad);
      const auto& [new1, new2] = pair;
      if (height > tolerance &&
          !flip_keeps_original_near(m, t1, quad->t2, {a, b, c, d}, pair, limit2))
        continue;
      if (!m.flip_keeps_witnesses(t1, quad->t2, new1, new2, {a, b, c, d}, limit2)) continue;
      m.commit_witnesses();
      apply_flip(m, t1, a, b, c, *quad);
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
      // The points the move makes: the vertex, its edges' midpoints and its triangles'
      // centroids.
      bool near = m.near_original(p, limit2, v);
      for (size_t k = 0; near && k < ring->size(); ++k)
        near = m.near_original(0.5 * (p + m.pos[(*ring)[k]]), limit2, v);
      for (uint32_t t : m.tris[v]) {
        if (!near) break;
        if (!m.alive_tri[t]) continue;
        const uint32_t* i = &m.s.mesh.indices[3 * size_t(t)];
        Vec3d sum{};
        for (int k = 0; k < 3; ++k) sum = sum + (i[k] == v ? p : m.pos[i[k]]);
        near = m.near_original((1.0 / 3.0) * sum, limit2, v);
      }
      if (!near) continue;
      if (!m.collapse_keeps_witnesses(v, v, p, limit2)) continue;
      m.commit_witnesses();
      m.pos[v] = p;
      ++moved;
    }
  }
  return moved;
}

}  // namespace segmesh
