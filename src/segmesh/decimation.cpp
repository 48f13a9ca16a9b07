#include "segmesh/decimation.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>
#include <bit>
#include <deque>

#include "segmesh/detail/edge_flips.hpp"
#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/detail/quadric.hpp"
#include "segmesh/detail/surface_roles.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {

namespace {

struct Candidate {
  double cost = 0;
  uint32_t remove = 0, keep = 0;
  Vec3d position;
  uint32_t remove_version = 0, keep_version = 0;
  // The heap's order: least cost first, ties by ids.
  bool operator<(const Candidate& o) const {
    if (cost != o.cost) return cost > o.cost;
    if (remove != o.remove) return remove > o.remove;
    return keep > o.keep;
  }
};

// The candidates by cost, cheapest first, in buckets 1/16 of an octave wide (4.4 %): a bucket is
// the top 16 bits of the cost's double (sign, exponent, 4 bits of mantissa), which order positive
// doubles as the doubles do. Costs at or below 2^-40 mm share the first bucket, above 2^24 the
// last. Within a bucket the last pushed comes first: the collapses near the last one, whose
// vertices are still in cache. A binary heap of the ~4 M candidates a million-triangle surface
// pushes spent more than half of the decimation in cache misses; pushing and popping here touch
// the ends of short arrays. Deterministic: the order depends only on the pushes.
class CostBuckets {
 public:
  CostBuckets() : buckets_(bucket(std::numeric_limits<double>::infinity()) + 1) {}
  bool empty() {
    while (first_ < buckets_.size() && buckets_[first_].empty()) ++first_;
    return first_ == buckets_.size();
  }
  void push(const Candidate& c) {
    const size_t b = bucket(c.cost);
    buckets_[b].push_back(c);
    first_ = std::min(first_, b);
  }
  // The cheapest bucket's last candidate, removed; call only when !empty().
  Candidate pop() {
    Candidate c = buckets_[first_].back();
    buckets_[first_].pop_back();
    return c;
  }

 private:
  static size_t bucket(double cost) {
    constexpr double lowest = 0x1p-40, highest = 0x1p24;
    const uint64_t base = std::bit_cast<uint64_t>(lowest) >> 48;
    if (!(cost > lowest)) return 0;
    return size_t((std::bit_cast<uint64_t>(std::min(cost, highest)) >> 48) - base);
  }
  std::vector<std::vector<Candidate>> buckets_;
  size_t first_ = 0;
};

// The edge flips after the collapses may move the surface by this share of error_mm (or of the
// largest collapse cost, when smaller); the collapses keep the original vertices within the rest,
// so the two together stay within error_mm.
constexpr double kFlipToleranceShare = 0.25;

constexpr double kMaxNormalTurnCos = 0.5;  // 60 degrees
constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kSliver = 0.02;  // decimation.hpp says why not 0.05
constexpr double kPlaneWeight = 1.0 / 3;

// Lists of vertex or triangle ids for the checks, reused: a check allocates nothing once the
// lists have grown (the allocations of fresh lists were a fifth of the decimation's time).
class ListPool {
 public:
  using List = std::vector<uint32_t>;
  // A cleared list, returned to the pool when the lease ends; bind it to a name.
  class Lease {
   public:
    Lease(ListPool& pool, List& list) : pool_(&pool), list_(&list) {}
    Lease(Lease&& o) noexcept : pool_(std::exchange(o.pool_, nullptr)), list_(o.list_) {}
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    Lease& operator=(Lease&&) = delete;
    ~Lease() {
      if (pool_) pool_->free_.push_back(list_);
    }
    List& operator*() const { return *list_; }
    List* operator->() const { return list_; }

   private:
    ListPool* pool_;
    List* list_;
  };
  Lease take() {
    if (free_.empty()) free_.push_back(&all_.emplace_back());
    List& list = *free_.back();
    free_.pop_back();
    list.clear();
    return Lease(*this, list);
  }

 private:
  std::deque<List> all_;  // stable addresses
  std::vector<List*> free_;
};

// An original vertex as a decimated vertex stands for it: where it was, and its witness (a live
// triangle within the bound; ~0u for a vertex of no triangle). Kept in the standing vertex's list,
// so a check reads them in a row.
struct Original {
  Vec3f position;
  uint32_t witness;
};

class Collapser {
 public:
  Collapser(LabelledSurface& s, const DecimateOptions& options, std::span<const int64_t> budgets,
            int64_t surface_budget)
      : s_(s), options_(options), limit_mm_(options.error_mm * (1 - kFlipToleranceShare)) {
    const size_t nv = s.mesh.positions.size(), nt = s.sides.size();
    pos_.resize(nv);
    for (size_t v = 0; v < nv; ++v) pos_[v] = to_double(s.mesh.positions[v]);
    role_ = surface_roles(s, InterfaceSides::either_way).smooth.role;
    junction_.assign(nv, 0);
    for (uint32_t v : s.junction_vertices) junction_[v] = 1;
    quadric_.resize(nv);
    absorbed_.resize(nv);
    for (uint32_t v = 0; v < nv; ++v) absorbed_[v].push_back({s.mesh.positions[v], ~0u});
    tris_.resize(nv);
    alive_tri_.assign(nt, 1);
    alive_vertex_.assign(nv, 1);
    version_.assign(nv, 0);
    count_.assign(s.part_count + 1, 0);
    budget_.assign(s.part_count + 1, 0);
    for (size_t p = 0; p < budgets.size() && p < s.part_count; ++p) budget_[p + 1] = budgets[p];
    surface_budget_ = surface_budget;
    has_budget_ = surface_budget_ > 0 ||
                  std::any_of(budget_.begin(), budget_.end(), [](int64_t b) { return b > 0; });
    for (uint32_t t = 0; t < nt; ++t) {
      const uint32_t* i = &s.mesh.indices[3 * size_t(t)];
      const Vec3d n = cross(pos_[i[1]] - pos_[i[0]], pos_[i[2]] - pos_[i[0]]);
      const double len = norm(n);
      if (len > 0) {
        const Vec3d u = (1 / len) * n;
        Quadric q = plane_quadric(u, -dot(u, pos_[i[0]]));
        for (double& x : q.q) x *= kPlaneWeight;
        for (int c = 0; c < 3; ++c) quadric_[i[c]] += q;
      }
      for (int c = 0; c < 3; ++c) {
        tris_[i[c]].push_back(t);
        absorbed_[i[c]][0].witness = t;  // distance 0
      }
      for (uint32_t m : s.sides[t])
        if (m != 0) ++count_[m];
    }
  }

  DecimationStats run() {
    for (uint32_t v = 0; v < pos_.size(); ++v) push_edges(v, /*higher_only=*/true);
    DecimationStats stats;
    while (!queue_.empty()) {
      const Candidate c = queue_.pop();
      if (!alive_vertex_[c.remove] || !alive_vertex_[c.keep] ||
          version_[c.remove] != c.remove_version || version_[c.keep] != c.keep_version)
        continue;
      const bool within_error = limit_mm_ > 0 && c.cost <= limit_mm_;
      if (!within_error && !has_budget_) continue;  // never pushed (push_edges)
      if (!within_error && !removes_from_part_over_budget(c.remove, c.keep)) continue;
      if (!allowed(c)) continue;
      // Beyond the error bound (a budget's collapse) the witnesses are only kept alive.
      if (!keeps_original_points(c, within_error ? limit_mm_ * limit_mm_ : kInfinity)) continue;
      if (crosses_nearby(c)) continue;
      apply(c);
      ++stats.collapses;
      stats.largest_cost_mm = std::max(stats.largest_cost_mm, c.cost);
    }
    compact();
    return stats;
  }

 private:

  bool has(uint32_t t, uint32_t v) const {
    const uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
    return i[0] == v || i[1] == v || i[2] == v;
  }

  // The live triangles on edge (a, b).
  template <class F>
  void for_edge_triangles(uint32_t a, uint32_t b, F&& f) const {
    for (uint32_t t : tris_[a])
      if (alive_tri_[t] && has(t, b)) f(t);
  }

  // A junction edge: its triangles separate two or more different pairs of materials.
  bool junction_edge(uint32_t a, uint32_t b) const {
    bool found = false, junction = false;
    std::array<uint32_t, 2> first{};
    for_edge_triangles(a, b, [&](uint32_t t) {
      if (!found) {
        first = s_.sides[t];
        found = true;
      } else if (!same_interface(s_.sides[t], first)) {
        junction = true;
      }
    });
    return junction;
  }

  // The neighbours of v over its live triangles that hold material m (all when m is ~0u),
  // sorted and unique.
  ListPool::Lease neighbours(uint32_t v, uint32_t m = ~0u) const {
    ListPool::Lease lease = pool_.take();
    std::vector<uint32_t>& out = *lease;
    for (uint32_t t : tris_[v]) {
      if (!alive_tri_[t]) continue;
      if (m != ~0u && s_.sides[t][0] != m && s_.sides[t][1] != m) continue;
      const uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
      for (int c = 0; c < 3; ++c)
        if (i[c] != v) out.push_back(i[c]);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return lease;
  }

  ListPool::Lease curve_neighbours(uint32_t v) const {
    ListPool::Lease out = pool_.take();
    const ListPool::Lease all = neighbours(v);
    for (uint32_t w : *all)
      if (junction_edge(v, w)) out->push_back(w);
    return out;
  }

  // The best collapse of edge (a, b), if the roles allow one.
  std::optional<Candidate> candidate(uint32_t a, uint32_t b) const {
    std::optional<Candidate> best;
    auto consider = [&](uint32_t u, uint32_t v) {
      if (role_[u] == SmoothRole::kFixed) return;
      Quadric q = quadric_[u];
      q += quadric_[v];
      Vec3d p = pos_[v];
      if (role_[u] == SmoothRole::kCurve) {
        if (!junction_edge(u, v)) return;
        if (role_[v] == SmoothRole::kCurve) p = best_on_segment(q, pos_[u], pos_[v]);
      } else if (role_[v] == SmoothRole::kSheet) {
        p = best_free(q, pos_[u], pos_[v]);
      }
      const Candidate c{cost_mm(q, p), u, v, p, version_[u], version_[v]};
      if (!best || *best < c) best = c;  // the heap's first: least cost, then ids
    };
    if (role_[a] == SmoothRole::kSheet && role_[b] == SmoothRole::kSheet) {
      consider(std::max(a, b), std::min(a, b));  // one placement, whichever vertex stays
    } else {
      consider(a, b);
      consider(b, a);
    }
    return best;
  }

  static Vec3d best_on_segment(const Quadric& q, Vec3d a, Vec3d b) {
    // Q(a + t (b - a)) = A t^2 + B t + C; the minimum on [0, 1] or an end.
    const double q0 = evaluate(q, a), q1 = evaluate(q, b), qh = evaluate(q, 0.5 * (a + b));
    const double A = 2 * (q0 + q1) - 4 * qh, B = q1 - q0 - A;
    double t = q0 <= q1 ? 0 : 1;
    if (A > 0) {
      const double s = std::clamp(-B / (2 * A), 0.0, 1.0);
      if (evaluate(q, a + s * (b - a)) < std::min(q0, q1)) t = s;
    }
    return a + t * (b - a);
  }

  static Vec3d best_free(const Quadric& q, Vec3d a, Vec3d b) {
    const Vec3d mid = 0.5 * (a + b);
    if (const auto x = optimum(q); x && norm(*x - mid) <= norm(b - a)) return *x;
    Vec3d best = mid;
    for (Vec3d p : {a, b})
      if (evaluate(q, p) < evaluate(q, best)) best = p;
    return best;
  }

  void push_edges(uint32_t v, bool higher_only) {
    const ListPool::Lease around = neighbours(v);
    for (uint32_t w : *around) {
      if (higher_only && w < v) continue;
      const auto c = candidate(v, w);
      // Without a budget a collapse above the error bound is never made: not worth a heap entry.
      if (c && (has_budget_ || c->cost <= limit_mm_)) queue_.push(*c);
    }
  }

  // Whether a collapse of (u, v) beyond the error bound is wanted: the shells hold more triangles
  // than the surface's budget, or a part whose triangles it removes is above its own.
  bool removes_from_part_over_budget(uint32_t u, uint32_t v) const {
    if (surface_budget_ > 0 && shell_triangles() > surface_budget_) return true;
    bool over = false;
    for_edge_triangles(u, v, [&](uint32_t t) {
      for (uint32_t m : s_.sides[t])
        if (m != 0 && budget_[m] > 0 && count_[m] > budget_[m]) over = true;
    });
    return over;
  }

  bool allowed(const Candidate& c) const {
    const uint32_t u = c.remove, v = c.keep;
    // Triangle counts: no part below the minimum.
    const ListPool::Lease removed_lease = pool_.take();
    std::vector<uint32_t>& removed = *removed_lease;
    for_edge_triangles(u, v, [&](uint32_t t) { removed.push_back(t); });
    if (removed.empty()) return false;
    for (size_t m = 1; m < count_.size(); ++m) {
      int64_t lost = 0;
      for (uint32_t t : removed) lost += (s_.sides[t][0] == m) + (s_.sides[t][1] == m);
      if (lost > 0 && count_[m] - lost < kMinPartTriangles) return false;
    }
    // Link conditions: on the whole surface and in every part's shell.
    auto apexes = [&](uint32_t m, std::vector<uint32_t>& out) {
      for (uint32_t t : removed) {
        if (m != ~0u && s_.sides[t][0] != m && s_.sides[t][1] != m) continue;
        const uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
        for (int k = 0; k < 3; ++k)
          if (i[k] != u && i[k] != v) out.push_back(i[k]);
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    };
    auto link_holds = [&](uint32_t m) {
      const ListPool::Lease nu = neighbours(u, m), nv = neighbours(v, m);
      if (nu->empty() || nv->empty()) return true;  // not both in this shell
      const ListPool::Lease common = pool_.take(), ap = pool_.take();
      std::set_intersection(nu->begin(), nu->end(), nv->begin(), nv->end(), std::back_inserter(*common));
      apexes(m, *ap);
      if (ap->empty()) return false;  // both in the shell, no edge of it between them
      return *common == *ap;
    };
    if (!link_holds(~0u)) return false;
    const ListPool::Lease materials_lease = pool_.take();
    std::vector<uint32_t>& materials = *materials_lease;
    for (uint32_t x : {u, v})
      for (uint32_t t : tris_[x])
        if (alive_tri_[t])
          for (uint32_t m : s_.sides[t])
            if (m != 0) materials.push_back(m);
    std::sort(materials.begin(), materials.end());
    materials.erase(std::unique(materials.begin(), materials.end()), materials.end());
    for (uint32_t m : materials)
      if (!link_holds(m)) return false;
    // A curve collapse must not close its curve into a loop of two edges.
    if (role_[u] == SmoothRole::kCurve) {
      const ListPool::Lease cu = curve_neighbours(u), cv = curve_neighbours(v);
      for (uint32_t w : *cu)
        if (w != v && std::find(cv->begin(), cv->end(), w) != cv->end()) return false;
    }
    // Geometry: no turned, degenerate or new sliver triangle.
    double worst_before = 1, worst_after = 1;
    for (uint32_t t : removed) worst_before = std::min(worst_before, rho(t));
    for (uint32_t x : {u, v}) {
      for (uint32_t t : tris_[x]) {
        if (!alive_tri_[t] || (has(t, u) && has(t, v))) continue;
        const uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
        Vec3d p[3];
        for (int k = 0; k < 3; ++k) p[k] = i[k] == u || i[k] == v ? c.position : pos_[i[k]];
        const Vec3d n0 = cross(pos_[i[1]] - pos_[i[0]], pos_[i[2]] - pos_[i[0]]);
        const Vec3d n1 = cross(p[1] - p[0], p[2] - p[0]);
        const double l0 = norm(n0), l1 = norm(n1);
        if (!(l1 > 1e-12 * (l0 + 1e-30))) return false;
        if (dot(n0, n1) < kMaxNormalTurnCos * l0 * l1) return false;
        worst_before = std::min(worst_before, rho(t));
        worst_after = std::min(worst_after, radii_ratio(p[0], p[1], p[2]));
      }
    }
    if (worst_after < kSliver && worst_after < worst_before) return false;
    return true;
  }

  // Every original vertex stays within limit_mm_ of a live triangle, its witness. A collapse
  // changes the triangles around u and v (moved, renumbered or gone); every original vertex whose
  // witness is one of them needs a new one among the triangles, as they will be after the
  // collapse, of the vertex that stands for it. When all find one the collapse keeps the bound
  // and the new witnesses wait in pending_ for apply. (A bound on the original vertices, not on
  // every point of the original triangles: the tests measure those.)
  bool keeps_original_points(const Candidate& c, double limit2) {
    const uint32_t u = c.remove, v = c.keep;
    pending_.clear();
    // The triangles the collapse changes: every witness stays a live triangle, so one not among
    // these keeps its place and distance.
    const ListPool::Lease changed = pool_.take();
    for (uint32_t x : {u, v})
      for (uint32_t t : tris_[x]) changed->push_back(t);
    const ListPool::Lease affected_lease = neighbours(u);
    std::vector<uint32_t>& affected = *affected_lease;
    {
      const ListPool::Lease nv = neighbours(v);
      affected.insert(affected.end(), nv->begin(), nv->end());
    }
    affected.push_back(u);
    affected.push_back(v);
    std::sort(affected.begin(), affected.end());
    affected.erase(std::unique(affected.begin(), affected.end()), affected.end());
    auto corner = [&](uint32_t i) { return i == u || i == v ? c.position : pos_[i]; };
    for (uint32_t x : affected) {
      bool have_fan = false;
      const std::vector<Original>& originals = absorbed_[x];
      for (uint32_t k = 0; k < originals.size(); ++k) {
        const uint32_t w = originals[k].witness;
        if (w == ~0u || std::find(changed->begin(), changed->end(), w) == changed->end()) continue;
        if (!have_fan) {
          // x's triangles after the collapse (u's and v's together for either of them).
          fan_.clear();
          for (uint32_t y : {x, x == u ? v : x == v ? u : x})
            for (uint32_t t : tris_[y]) {
              if (!alive_tri_[t] || (has(t, u) && has(t, v))) continue;
              const uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
              fan_.push_back({t, {corner(i[0]), corner(i[1]), corner(i[2])}});
            }
          have_fan = true;
        }
        const Vec3d q = to_double(originals[k].position);
        uint32_t found = ~0u;
        for (const auto& [t, p] : fan_) {
          const Vec3d d = closest_point_on_triangle(q, p[0], p[1], p[2]) - q;
          if (dot(d, d) <= limit2) {
            found = t;
            break;
          }
        }
        if (found == ~0u) return false;
        pending_.push_back({x, k, found});
      }
    }
    return true;
  }

  // Near where interfaces meet (the triangles within two rings of the edge are of more than one
  // interface), whether a triangle around the merged vertex would cross one of those triangles:
  // a sheet folded through another part's.
  bool crosses_nearby(const Candidate& c) const {
    const uint32_t u = c.remove, v = c.keep;
    // Sheet vertices all around: every triangle within two rings is of their one interface.
    const ListPool::Lease near_lease = neighbours(u);
    std::vector<uint32_t>& near = *near_lease;
    {
      const ListPool::Lease nv = neighbours(v);
      near.insert(near.end(), nv->begin(), nv->end());
    }
    if (std::all_of(near.begin(), near.end(), [&](uint32_t w) { return role_[w] == SmoothRole::kSheet; }))
      return false;
    const ListPool::Lease ring_lease = pool_.take();
    std::vector<uint32_t>& ring = *ring_lease;
    for (uint32_t w : near)
      for (uint32_t t : tris_[w])
        if (alive_tri_[t] && !(has(t, u) && has(t, v))) ring.push_back(t);
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    bool mixed = false;
    for (uint32_t t : ring) mixed = mixed || !same_interface(s_.sides[t], s_.sides[ring[0]]);
    if (!mixed) return false;
    auto corner = [&](uint32_t i) { return i == u || i == v ? c.position : pos_[i]; };
    auto id = [&](uint32_t i) { return i == u ? v : i; };
    for (uint32_t f : ring) {
      const uint32_t* fi = &s_.mesh.indices[3 * size_t(f)];
      if (!has(f, u) && !has(f, v)) continue;  // not around the merged vertex
      const uint32_t fa = id(fi[0]), fb = id(fi[1]), fc = id(fi[2]);
      const Vec3d p[3] = {corner(fi[0]), corner(fi[1]), corner(fi[2])};
      for (uint32_t r : ring) {
        const uint32_t* ri = &s_.mesh.indices[3 * size_t(r)];
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

  double rho(uint32_t t) const {
    const uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
    return radii_ratio(pos_[i[0]], pos_[i[1]], pos_[i[2]]);
  }

  void apply(const Candidate& c) {
    const uint32_t u = c.remove, v = c.keep;
    for (uint32_t t : tris_[u]) {
      if (!alive_tri_[t]) continue;
      uint32_t* i = &s_.mesh.indices[3 * size_t(t)];
      if (has(t, v)) {
        alive_tri_[t] = 0;
        for (uint32_t m : s_.sides[t])
          if (m != 0) --count_[m];
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (i[k] == u) i[k] = v;
      tris_[v].push_back(t);
    }
    std::vector<uint32_t>().swap(tris_[u]);
    alive_vertex_[u] = 0;
    ++version_[u];
    ++version_[v];
    pos_[v] = c.position;
    quadric_[v] += quadric_[u];
    for (const PendingWitness& w : pending_) absorbed_[w.vertex][w.index].witness = w.triangle;
    if (absorbed_[v].size() < absorbed_[u].size()) absorbed_[v].swap(absorbed_[u]);
    absorbed_[v].insert(absorbed_[v].end(), absorbed_[u].begin(), absorbed_[u].end());
    std::vector<Original>().swap(absorbed_[u]);
    junction_[v] |= junction_[u];  // where the shell may touch itself, v now stands
    // Dead triangles leave the lists of the vertices around.
    {
      const ListPool::Lease around = neighbours(v);
      for (uint32_t w : *around) prune(w);
    }
    prune(v);
    push_edges(v, false);
  }

  void prune(uint32_t v) {
    auto& list = tris_[v];
    list.erase(std::remove_if(list.begin(), list.end(), [&](uint32_t t) { return !alive_tri_[t]; }),
               list.end());
  }

  void compact() {
    const size_t nv = pos_.size(), nt = s_.sides.size();
    std::vector<uint32_t> id(nv, ~0u);
    std::vector<char> used(nv, 0);
    for (size_t t = 0; t < nt; ++t)
      if (alive_tri_[t])
        for (int k = 0; k < 3; ++k) used[s_.mesh.indices[3 * t + size_t(k)]] = 1;
    std::vector<Vec3f> positions;
    for (size_t v = 0; v < nv; ++v)
      if (used[v]) {
        id[v] = static_cast<uint32_t>(positions.size());
        positions.push_back(to_float(pos_[v]));
      }
    std::vector<uint32_t> indices;
    std::vector<std::array<uint32_t, 2>> sides;
    for (size_t t = 0; t < nt; ++t) {
      if (!alive_tri_[t]) continue;
      for (int k = 0; k < 3; ++k) indices.push_back(id[s_.mesh.indices[3 * t + size_t(k)]]);
      sides.push_back(s_.sides[t]);
    }
    std::vector<uint32_t> junction;
    for (size_t v = 0; v < nv; ++v)
      if (junction_[v] && id[v] != ~0u) junction.push_back(id[v]);
    s_.mesh.positions = std::move(positions);
    s_.mesh.indices = std::move(indices);
    s_.mesh.normals.clear();
    s_.mesh.colors.clear();
    s_.sides = std::move(sides);
    s_.junction_vertices = std::move(junction);
  }

  LabelledSurface& s_;
  const DecimateOptions& options_;
  std::vector<Vec3d> pos_;
  std::vector<SmoothRole> role_;
  std::vector<char> junction_;  // the surface's junction_vertices and the vertices they merged into
  std::vector<Quadric> quadric_;
  std::vector<std::vector<Original>> absorbed_;  // the original vertices each vertex stands for
  // A new witness for absorbed_[vertex][index], found by the last check, set by apply.
  struct PendingWitness {
    uint32_t vertex, index, triangle;
  };
  std::vector<PendingWitness> pending_;
  mutable ListPool pool_;
  std::vector<std::pair<uint32_t, std::array<Vec3d, 3>>> fan_;  // scratch
  double limit_mm_ = 0;
  std::vector<std::vector<uint32_t>> tris_;
  std::vector<char> alive_tri_, alive_vertex_;
  std::vector<uint32_t> version_;
  std::vector<int64_t> count_, budget_;  // by material
  int64_t surface_budget_ = 0;           // for the shells' triangles together
  bool has_budget_ = false;

  int64_t shell_triangles() const { return std::accumulate(count_.begin() + 1, count_.end(), int64_t{0}); }
  CostBuckets queue_;
};


}  // namespace

std::optional<DecimateOptionsProblem> decimate_options_problem(const DecimateOptions& o) {
  if (!(o.error_mm >= 0) || !std::isfinite(o.error_mm))
    return DecimateOptionsProblem{"decimate-error", "must be a non-negative number of millimetres"};
  if (o.max_triangles < 0)
    return DecimateOptionsProblem{"max-triangles", "must not be negative (0: no budget)"};
  if (o.max_triangles_per_part < 0)
    return DecimateOptionsProblem{"max-triangles-per-part", "must not be negative (0: no budget)"};
  return std::nullopt;
}

std::vector<int64_t> part_triangle_budgets(const std::vector<double>& areas,
                                           const DecimateOptions& o) {
  const double total = std::accumulate(areas.begin(), areas.end(), 0.0);
  std::vector<int64_t> out(areas.size(), 0);
  for (size_t p = 0; p < areas.size(); ++p) {
    int64_t b = 0;
    if (o.max_triangles > 0 && total > 0) {
      // Rounded down, so the parts' budgets add up to at most the scene's.
      b = std::max<int64_t>(1, int64_t(std::floor(double(o.max_triangles) * areas[p] / total)));
    }
    if (o.max_triangles_per_part > 0) b = b > 0 ? std::min(b, o.max_triangles_per_part)
                                                : o.max_triangles_per_part;
    out[p] = b;
  }
  return out;
}

DecimationStats decimate_surface(LabelledSurface& surface, const DecimateOptions& options,
                                 std::span<const int64_t> budgets, int64_t surface_budget) {
  if (!options.active() || surface.sides.empty()) return {};
  DecimationStats stats = Collapser(surface, options, budgets, surface_budget).run();
  const double tolerance =
      kFlipToleranceShare * std::min(stats.largest_cost_mm,
                                     options.error_mm > 0 ? options.error_mm : stats.largest_cost_mm);
  stats.flips = improve_by_edge_flips(surface, tolerance);
  return stats;
}

DecimationStats decimate_scene(Scene& scene, const DecimateOptions& options) {
  if (!options.active()) return {};
  if (scene.surface) {
    // One surface, one order of collapses: the scene's budget is the surface's, so the error
    // evens out over the parts instead of each part stopping at its area's share.
    const std::vector<int64_t> per_part(scene.parts.size(), options.max_triangles_per_part);
    const DecimationStats stats =
        decimate_surface(*scene.surface, options, per_part, options.max_triangles);
    set_part_shells(scene);
    return stats;
  }
  std::vector<double> areas;
  for (const Part& part : scene.parts) areas.push_back(surface_area(part.mesh));
  const std::vector<int64_t> budgets = part_triangle_budgets(areas, options);
  std::vector<DecimationStats> each(scene.parts.size());
  tbb::parallel_for(size_t{0}, scene.parts.size(), [&](size_t p) {
    TriMesh& mesh = scene.parts[p].mesh;
    if (mesh.empty()) return;
    LabelledSurface one;
    one.mesh.positions = std::move(mesh.positions);
    one.mesh.indices = std::move(mesh.indices);
    one.sides.assign(one.mesh.indices.size() / 3, {1, 0});
    one.part_count = 1;
    const int64_t budget[1] = {budgets[p]};
    each[p] = decimate_surface(one, options, budget);
    mesh = TriMesh{};
    mesh.positions = std::move(one.mesh.positions);
    mesh.indices = std::move(one.mesh.indices);
    compute_vertex_normals(mesh);
  });
  DecimationStats stats;
  for (const DecimationStats& s : each) {
    stats.collapses += s.collapses;
    stats.flips += s.flips;
    stats.largest_cost_mm = std::max(stats.largest_cost_mm, s.largest_cost_mm);
  }
  return stats;
}

}  // namespace segmesh
