#include "segmesh/detail/decimation_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/detail/surface_roles.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {
constexpr double kPlaneWeight = 1.0 / 3;
// The shift of a triangle removed or replaced: its witnesses need a new search.
constexpr double kInfinityShift = std::numeric_limits<double>::infinity();
}  // namespace

// Room for four more triangles than a vertex starts with: a collapse into it adds the other
// vertex's before the dead ones are pruned.
void VertexTriangles::build(size_t nv, const std::vector<uint32_t>& indices, size_t nt) {
  constexpr uint32_t kSlack = 4;
  head_.assign(nv, Head{});
  for (size_t k = 0; k < 3 * nt; ++k) ++head_[indices[k]].cap;
  uint32_t start = 0;
  for (Head& h : head_) {
    h.start = start;
    h.cap += kSlack;
    start += h.cap;
  }
  data_.assign(start, 0);
  for (uint32_t t = 0; t < nt; ++t)
    for (int c = 0; c < 3; ++c) {
      Head& h = head_[indices[3 * size_t(t) + size_t(c)]];
      data_[h.start + h.size++] = t;
    }
}

// A list that outgrows its room moves to `start` with room for `need` or twice its room.
uint32_t VertexTriangles::relocate(uint32_t v, uint32_t need, size_t start) {
  Head& h = head_[v];
  const uint32_t cap = std::max(need, 2 * h.cap);
  std::copy_n(data_.begin() + h.start, h.size, data_.begin() + ptrdiff_t(start));
  h.start = uint32_t(start);
  h.cap = cap;
  return cap;
}

void VertexTriangles::move(uint32_t v, uint32_t need) {
  const size_t start = data_.size();
  data_.resize(start + std::max(need, 2 * head_[v].cap));
  relocate(v, need, start);
}

VertexTriangles::Room VertexTriangles::take_room(size_t entries) {
  const size_t start = data_.size();
  const size_t end = std::min<size_t>(start + entries, std::numeric_limits<uint32_t>::max());
  data_.resize(end);
  return {start, end};
}

bool VertexTriangles::try_room(uint32_t v, uint32_t size, Room& room) {
  if (size <= head_[v].cap) return true;
  if (room.next + std::max(size, 2 * head_[v].cap) > room.end) return false;
  room.next += relocate(v, size, room.next);
  return true;
}

bool DecimationMesh::near_original(const Vec3d& p, double limit2, uint32_t v) {
  if (!original) return true;
  size_t found =
      original->hint[v] == kNoTriangle ? OrderedTriangleTree::kNoStart : original->hint[v];
  const double d2 =
      original->tree->nearest2(p, std::numeric_limits<double>::infinity(), found, limit2, &found);
  original->hint[v] = uint32_t(found);
  return d2 <= limit2;
}

DecimationMesh::DecimationMesh(LabelledSurface& surface, bool witnessing_)
    : s(surface), witnessing(witnessing_) {
  const size_t nv = s.mesh.positions.size(), nt = s.sides.size();
  pos.resize(nv);
  for (size_t v = 0; v < nv; ++v) pos[v] = to_double(s.mesh.positions[v]);
  role = surface_roles(s, InterfaceSides::either_way).smooth.role;
  junction_vertex.assign(nv, 0);
  for (uint32_t v : s.junction_vertices) junction_vertex[v] = 1;
  quadric.resize(nv);
  if (witnessing && nt > 0) {
    original = std::make_unique<Original>();
    original->positions = s.mesh.positions;
    original->indices = s.mesh.indices;
    original->hint = first_triangles(s.mesh.indices.data(), nt, nv);
    original->tree.emplace(original->positions.data(), original->indices.data(), nt);
  }
  std::vector<char> has_witness(witnessing ? nv : 0, 0);
  if (witnessing) witnesses = std::vector<TriangleWitnesses>(nt);
  tris.build(nv, s.mesh.indices, nt);
  alive_tri.assign(nt, 1);
  alive_vertex.assign(nv, 1);
  for (uint32_t t = 0; t < nt; ++t) {
    const uint32_t* i = &s.mesh.indices[3 * size_t(t)];
    const Vec3d n = cross(pos[i[1]] - pos[i[0]], pos[i[2]] - pos[i[0]]);
    const double len = norm(n);
    if (len > 0) {
      const Vec3d u = (1 / len) * n;
      Quadric q = plane_quadric(u, -dot(u, pos[i[0]]));
      for (double& x : q.q) x *= kPlaneWeight;
      for (int c = 0; c < 3; ++c) quadric[i[c]] += q;
    }
    for (int c = 0; c < 3 && witnessing; ++c) {
      if (!has_witness[i[c]]) {  // a corner of its witness: distance 0
        has_witness[i[c]] = 1;
        witnesses[t].push_back({s.mesh.positions[i[c]], 0.0f});
      }
    }
  }
}

// A junction edge: its triangles separate two or more different pairs of materials.
bool DecimationMesh::junction_edge(uint32_t a, uint32_t b) const {
  bool found = false, mixed = false;
  std::array<uint32_t, 2> first{};
  for_edge_triangles(a, b, [&](uint32_t t) {
    if (!found) {
      first = s.sides[t];
      found = true;
    } else if (!same_interface(s.sides[t], first)) {
      mixed = true;
    }
  });
  return mixed;
}

// The neighbours of v over its live triangles that hold material m (all when m is ~0u),
// sorted and unique.
ListPool::Lease DecimationMesh::neighbours(uint32_t v, uint32_t m) const {
  ListPool::Lease lease = pool().take();
  std::vector<uint32_t>& out = *lease;
  for (uint32_t t : tris[v]) {
    if (!alive_tri[t]) continue;
    if (m != ~0u && s.sides[t][0] != m && s.sides[t][1] != m) continue;
    const uint32_t* i = &s.mesh.indices[3 * size_t(t)];
    for (int c = 0; c < 3; ++c)
      if (i[c] != v) out.push_back(i[c]);
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return lease;
}

ListPool::Lease DecimationMesh::curve_neighbours(uint32_t v) const {
  ListPool::Lease out = pool().take();
  const ListPool::Lease all = neighbours(v);
  for (uint32_t w : *all)
    if (junction_edge(v, w)) out->push_back(w);
  return out;
}

double DecimationMesh::rho(uint32_t t) const {
  const uint32_t* i = &s.mesh.indices[3 * size_t(t)];
  return radii_ratio(pos[i[0]], pos[i[1]], pos[i[2]]);
}


// Witnesses (decimation.hpp). Every original vertex keeps a witness, a live triangle within
// the bound; witnesses lists them per triangle. A change (collapse, flip, move) that alters
// `changed` triangles needs a new witness for every original vertex those witness. Cheapest
// first: the same triangle when its distance bound plus the triangle's `shift` (how far its one
// moved corner goes; infinity for a triangle removed or replaced) stays within the limit; else
// the same triangle as it will be, measured exactly; else the first within the limit among the
// triangles near the change as they will be (fan), or among those one ring further (fill_far
// adds them to fan). The new witnesses wait in pending for commit_witnesses.
template <class Shift, class FillFar>
bool DecimationMesh::rewitness(std::span<const uint32_t> changed, double limit2, Shift&& shift,
                               FillFar&& fill_far) {
  std::vector<PendingWitness>& pending = scratch().pending;
  const std::vector<FanTriangle>& fan = scratch().fan;
  std::vector<ChangedTriangle>& changed_out = scratch().pending_changed;
  pending.clear();
  changed_out.clear();
  const double limit = std::sqrt(limit2);
  bool far = false;
  for (uint32_t t : changed) {
    const double moved = shift(t);
    const TriangleWitnesses& tw = witnesses[t];
    if (moved < kInfinityShift && tw.reach + moved <= limit) {
      changed_out.push_back({t, true, moved});
      continue;
    }
    changed_out.push_back({t, false, 0.0});
    const double offset = tw.offset;
    const FanTriangle* own = nullptr;  // t as it will be, found when first needed
    bool own_looked = false;
    for (const auto& [original, distance_before] : tw) {
      const double bound = double(distance_before) + offset + moved;
      if (moved < kInfinityShift && bound <= limit) {
        pending.push_back({original, t, bound});
        continue;
      }
      const Vec3d q = to_double(original);
      if (!own_looked && moved < kInfinityShift) {
        for (const FanTriangle& f : fan)
          if (f.t == t) own = &f;
        own_looked = true;
      }
      if (own) {
        const double d2 = point_triangle_distance2(q, own->p[0], own->p[1], own->p[2]);
        if (d2 <= limit2) {
          pending.push_back({original, t, std::sqrt(d2)});
          continue;
        }
      }
      double distance = 0;
      uint32_t found = witness_in_fan(q, limit2, distance);
      if (found == ~0u && !far) {
        fill_far();
        far = true;
        own = nullptr;  // the fan may have moved
        own_looked = false;
        found = witness_in_fan(q, limit2, distance);
      }
      if (found == ~0u) return false;
      pending.push_back({original, found, distance});
    }
  }
  return true;
}

void DecimationMesh::commit_witnesses() {
  if (!witnessing) return;
  const DecimationScratch& sc = scratch();
  for (const ChangedTriangle& c : sc.pending_changed) {
    if (c.whole) {
      witnesses[c.t].offset += c.shift;
      witnesses[c.t].reach += c.shift;
    } else {
      witnesses[c.t].clear();
      witnesses[c.t].offset = 0;
      witnesses[c.t].reach = 0;
    }
  }
  // Entries relative to the offset, rounded up to float: their bounds stay upper bounds.
  for (const PendingWitness& w : sc.pending) {
    TriangleWitnesses& tw = witnesses[w.t];
    const double relative = w.distance - tw.offset;
    float d = float(relative);
    if (double(d) < relative) d = std::nextafter(d, std::numeric_limits<float>::infinity());
    tw.push_back({w.position, d});
    tw.reach = std::max(tw.reach, w.distance);
  }
}

// fan += the live triangles of `y` other than `skip` (and those on edge (u, v) when
// `collapse`), their corners through `corner`.
template <class Corner>
void DecimationMesh::add_fan(uint32_t y, Corner&& corner, bool collapse, uint32_t u, uint32_t v,
                             uint32_t skip1, uint32_t skip2) {
  for (uint32_t t : tris[y]) {
    if (t == skip1 || t == skip2 || !(collapse ? kept_by_collapse(t, u, v) : alive_tri[t])) continue;
    const uint32_t* i = &s.mesh.indices[3 * size_t(t)];
    add_to_fan(t, corner(i[0]), corner(i[1]), corner(i[2]));
  }
}

// The collapse of u into v at `position` (u == v: the move of v to `position`).
bool DecimationMesh::collapse_keeps_witnesses(uint32_t u, uint32_t v, Vec3d position,
                                              double limit2) {
  const bool collapse = u != v;
  if (!witnessing) {
    // What the witnesses refused even without a bound: a collapse that leaves no live triangle
    // around the merged vertex nor one ring further (a closed piece of the surface of two
    // triangles, collapsed to nothing).
    if (!collapse) return true;
    auto outside_edge = [&](uint32_t y) {
      for (uint32_t t : tris[y])
        if (kept_by_collapse(t, u, v)) return true;
      return false;
    };
    if (outside_edge(u) || outside_edge(v)) return true;
    for (uint32_t y : {u, v}) {
      const ListPool::Lease ring = neighbours(y);
      for (uint32_t w : *ring)
        if (w != u && w != v && outside_edge(w)) return true;
    }
    return false;
  }
  const ListPool::Lease changed = pool().take();
  // The vertices whose triangles change: v, and u too in a collapse (a move has u == v).
  const std::array<uint32_t, 2> around{v, u};
  const size_t count = collapse ? 2 : 1;
  for (size_t k = 0; k < count; ++k)
    for (uint32_t t : tris[around[k]])
      if (alive_tri[t]) changed->push_back(t);
  std::sort(changed->begin(), changed->end());
  changed->erase(std::unique(changed->begin(), changed->end()), changed->end());
  auto corner = [&](uint32_t i) { return i == u || i == v ? position : pos[i]; };
  scratch().fan.clear();
  add_fan(v, corner, collapse, u, v);
  if (collapse) add_fan(u, corner, collapse, u, v);
  // A triangle around v keeps its corners but v's, which goes to `position`; around u the same
  // for u's; those on the edge go.
  const double v_moves = norm(position - pos[v]), u_moves = norm(position - pos[u]);
  auto shift = [&](uint32_t t) {
    const bool with_u = collapse && has(t, u), with_v = has(t, v);
    if (with_u && with_v) return kInfinityShift;
    return with_v ? v_moves : u_moves;
  };
  return rewitness(*changed, limit2, shift, [&] {
    for (size_t k = 0; k < count; ++k) {
      const ListPool::Lease ring = neighbours(around[k]);
      for (uint32_t w : *ring)
        if (w != u && w != v) add_fan(w, corner, collapse, u, v);
    }
  });
}

// The flip of t1 and t2 into `new1` and `new2` over the quad's `corners`.
bool DecimationMesh::flip_keeps_witnesses(uint32_t t1, uint32_t t2, const std::array<uint32_t, 3>& new1,
                          const std::array<uint32_t, 3>& new2,
                          const std::array<uint32_t, 4>& corners, double limit2) {
  if (!witnessing) return true;
  auto corner = [&](uint32_t i) { return pos[i]; };
  scratch().fan.clear();
  add_to_fan(t1, pos[new1[0]], pos[new1[1]], pos[new1[2]]);
  add_to_fan(t2, pos[new2[0]], pos[new2[1]], pos[new2[2]]);
  const uint32_t changed[2] = {t1, t2};
  auto replaced = [](uint32_t) { return kInfinityShift; };
  return rewitness(changed, limit2, replaced, [&] {
    for (uint32_t x : corners) add_fan(x, corner, false, 0, 0, t1, t2);
  });
}

void DecimationMesh::add_to_fan(uint32_t t, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
  scratch().fan.push_back({t,
                 {a, b, c},
                 {std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y}), std::min({a.z, b.z, c.z})},
                 {std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y}), std::max({a.z, b.z, c.z})}});
}

// The first triangle of fan within sqrt(limit2) of q, or ~0u. Most triangles of a fan are
// decided without the exact test: a box (made once per fan) farther than the limit rejects, a
// corner within it accepts (the triangle's closest point is no farther than its corners).
uint32_t DecimationMesh::witness_in_fan(const Vec3d& q, double limit2, double& distance) const {
  const double r = std::sqrt(limit2);
  for (const FanTriangle& f : scratch().fan) {
    if (q.x < f.lo.x - r || q.x > f.hi.x + r || q.y < f.lo.y - r || q.y > f.hi.y + r ||
        q.z < f.lo.z - r || q.z > f.hi.z + r)
      continue;
    const std::array<Vec3d, 3>& p = f.p;
    const double corner2 = nearest_corner_distance2(q, p[0], p[1], p[2]);
    if (corner2 <= limit2) {
      distance = std::sqrt(corner2);
      return f.t;
    }
    const double d2 = point_triangle_distance2(q, p[0], p[1], p[2]);
    if (d2 <= limit2) {
      distance = std::sqrt(d2);
      return f.t;
    }
  }
  return ~0u;
}


// Near where interfaces meet (the triangles within two rings of the edge are of more than one
// interface), whether a triangle around the merged vertex would cross one of those triangles:
// a sheet folded through another part's.
bool DecimationMesh::crosses_nearby(uint32_t u, uint32_t v, const Vec3d& position) const {
  // Sheet vertices all around: every triangle within two rings is of their one interface.
  bool all_sheet = true;
  for (uint32_t x : {u, v})
    for (uint32_t t : tris[x])
      if (alive_tri[t])
        for (int k = 0; k < 3; ++k) {
          const uint32_t w = s.mesh.indices[3 * size_t(t) + size_t(k)];
          all_sheet = all_sheet && role[w] == SmoothRole::kSheet;
        }
  if (all_sheet) return false;
  const ListPool::Lease near_lease = neighbours(u);
  std::vector<uint32_t>& near = *near_lease;
  {
    const ListPool::Lease nv = neighbours(v);
    near.insert(near.end(), nv->begin(), nv->end());
  }
  const ListPool::Lease ring_lease = pool().take();
  std::vector<uint32_t>& ring = *ring_lease;
  for (uint32_t w : near)
    for (uint32_t t : tris[w])
      if (kept_by_collapse(t, u, v)) ring.push_back(t);
  std::sort(ring.begin(), ring.end());
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  bool mixed = false;
  for (uint32_t t : ring) mixed = mixed || !same_interface(s.sides[t], s.sides[ring[0]]);
  if (!mixed) return false;
  auto corner = [&](uint32_t i) { return i == u || i == v ? position : pos[i]; };
  auto id = [&](uint32_t i) { return i == u ? v : i; };
  for (uint32_t f : ring) {
    const uint32_t* fi = &s.mesh.indices[3 * size_t(f)];
    if (!has(f, u) && !has(f, v)) continue;  // not around the merged vertex
    const uint32_t fa = id(fi[0]), fb = id(fi[1]), fc = id(fi[2]);
    const Vec3d p[3] = {corner(fi[0]), corner(fi[1]), corner(fi[2])};
    for (uint32_t r : ring) {
      const uint32_t* ri = &s.mesh.indices[3 * size_t(r)];
      bool shares = false;
      for (int k = 0; k < 3; ++k) {
        const uint32_t x = id(ri[k]);
        shares = shares || x == fa || x == fb || x == fc;
      }
      if (shares) continue;
      const Vec3d q[3] = {corner(ri[0]), corner(ri[1]), corner(ri[2])};
      for (int k = 0; k < 3; ++k) {
        if (segment_crosses_triangle(p[k], p[(k + 1) % 3], q[0], q[1], q[2]) ||
            segment_crosses_triangle(q[k], q[(k + 1) % 3], p[0], p[1], p[2]))
          return true;
      }
    }
  }
  return false;
}

void DecimationMesh::prune(uint32_t v) {
  tris.erase_if(v, [&](uint32_t t) { return !alive_tri[t]; });
}

void DecimationMesh::compact() {
  const size_t nv = pos.size(), nt = s.sides.size();
  std::vector<uint32_t> id(nv, ~0u);
  std::vector<char> used(nv, 0);
  for (size_t t = 0; t < nt; ++t)
    if (alive_tri[t])
      for (int k = 0; k < 3; ++k) used[s.mesh.indices[3 * t + size_t(k)]] = 1;
  std::vector<Vec3f> positions;
  for (size_t v = 0; v < nv; ++v)
    if (used[v]) {
      id[v] = static_cast<uint32_t>(positions.size());
      positions.push_back(to_float(pos[v]));
    }
  std::vector<uint32_t> indices;
  std::vector<std::array<uint32_t, 2>> sides;
  for (size_t t = 0; t < nt; ++t) {
    if (!alive_tri[t]) continue;
    for (int k = 0; k < 3; ++k) indices.push_back(id[s.mesh.indices[3 * t + size_t(k)]]);
    sides.push_back(s.sides[t]);
  }
  std::vector<uint32_t> junctions;
  for (size_t v = 0; v < nv; ++v)
    if (junction_vertex[v] && id[v] != ~0u) junctions.push_back(id[v]);
  s.mesh.positions = std::move(positions);
  s.mesh.indices = std::move(indices);
  s.mesh.normals.clear();
  s.mesh.colors.clear();
  s.sides = std::move(sides);
  s.junction_vertices = std::move(junctions);
}

}  // namespace segmesh
