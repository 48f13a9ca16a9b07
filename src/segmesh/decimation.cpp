#include "segmesh/decimation.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "segmesh/detail/decimation_mesh.hpp"
#include "segmesh/detail/decimation_passes.hpp"
#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/detail/quadric.hpp"
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

// An edge flip may move the surface by this share of error_mm (or of the largest collapse cost,
// when smaller): the height of the tetrahedron of the two diagonals.
constexpr double kFlipToleranceShare = 0.25;
// Rounds of one flip pass and one relaxation pass after the collapses, until neither changes.
constexpr int kImproveRounds = 4;
// The witnesses keep the original vertices within this share of error_mm: the points between
// them (the original triangles' insides, 0.244 mm for 0.2 asked on the test-size phantom's plate
// with the full bound) and the decimated triangles' insides (which the quadrics bound only at
// the vertices) need the rest.
constexpr double kWitnessShare = 0.80;

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kSliver = 0.02;  // decimation.hpp says why not 0.05

class Collapser {
 public:
  Collapser(LabelledSurface& s, const DecimateOptions& options, std::span<const int64_t> budgets,
            int64_t surface_budget)
      : m_(s), options_(options), limit_mm_(options.error_mm * kWitnessShare) {
    version_.assign(m_.pos.size(), 0);
    count_.assign(s.part_count + 1, 0);
    budget_.assign(s.part_count + 1, 0);
    for (size_t p = 0; p < budgets.size() && p < s.part_count; ++p) budget_[p + 1] = budgets[p];
    surface_budget_ = surface_budget;
    has_budget_ = surface_budget_ > 0 ||
                  std::any_of(budget_.begin(), budget_.end(), [](int64_t b) { return b > 0; });
    for (const std::array<uint32_t, 2>& sides : s.sides)
      for (uint32_t m : sides)
        if (m != 0) ++count_[m];
  }

  DecimationStats run() {
    for (uint32_t v = 0; v < m_.pos.size(); ++v) push_edges(v, /*higher_only=*/true);
    DecimationStats stats;
    while (!queue_.empty()) {
      const Candidate c = queue_.pop();
      if (!m_.alive_vertex[c.remove] || !m_.alive_vertex[c.keep] ||
          version_[c.remove] != c.remove_version || version_[c.keep] != c.keep_version)
        continue;
      const bool within_error = limit_mm_ > 0 && c.cost <= limit_mm_;
      if (!within_error && !has_budget_) continue;  // never pushed (push_edges)
      if (!within_error && !removes_from_part_over_budget(c.remove, c.keep)) continue;
      if (!allowed(c)) continue;
      // Beyond the error bound (a budget's collapse) the witnesses are only kept alive.
      if (!m_.collapse_keeps_witnesses(c.remove, c.keep, c.position,
                                       within_error ? limit_mm_ * limit_mm_ : kInfinity))
        continue;
      if (crosses_nearby(c)) continue;
      apply(c);
      ++stats.collapses;
      stats.largest_cost_mm = std::max(stats.largest_cost_mm, c.cost);
    }
    // Better triangles: flips and relaxation in turn, both keeping every witness.
    const double bound = limit_mm_ > 0 ? std::min(limit_mm_, stats.largest_cost_mm) : stats.largest_cost_mm;
    const double limit2 = limit_mm_ > 0 ? limit_mm_ * limit_mm_ : kInfinity;
    const double move_bound = limit_mm_ > 0 ? limit_mm_ : stats.largest_cost_mm;
    for (int round = 0; round < kImproveRounds; ++round) {
      const int64_t flips = flip_pass(m_, kFlipToleranceShare * bound, bound, limit2);
      const int64_t moves = relax_pass(m_, move_bound, limit2);
      const int64_t slivers = sliver_pass(move_bound, limit2);
      stats.flips += flips;
      stats.relaxed += moves;
      stats.collapses += slivers;
      if (flips == 0 && moves == 0 && slivers == 0) break;
    }
    m_.compact();
    return stats;
  }

  // Collapses that remove a sliver (radii ratio below kDecimationSliverRho), out of the cost order: the
  // edges of each sliver, shortest first, when the roles allow a collapse whose cost stays within
  // `bound` and every check of the collapse loop passes. Returns the collapses made.
  int64_t sliver_pass(double bound, double limit2) {
    int64_t made = 0;
    for (uint32_t t = 0; t < m_.alive_tri.size(); ++t) {
      if (!m_.alive_tri[t] || m_.rho(t) >= kDecimationSliverRho) continue;
      const uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
      std::array<std::pair<double, int>, 3> edges;
      for (int k = 0; k < 3; ++k) edges[size_t(k)] = {norm(m_.pos[i[(k + 1) % 3]] - m_.pos[i[k]]), k};
      std::sort(edges.begin(), edges.end());
      for (const auto& [length, k] : edges) {
        const std::optional<Candidate> c = candidate(i[k], i[(k + 1) % 3]);
        if (!c || c->cost > bound || !allowed(*c) ||
            !m_.collapse_keeps_witnesses(c->remove, c->keep, c->position, limit2) ||
            crosses_nearby(*c))
          continue;
        apply(*c);
        ++made;
        break;
      }
    }
    return made;
  }

 private:

  // The best collapse of edge (a, b), if the roles allow one.
  std::optional<Candidate> candidate(uint32_t a, uint32_t b) const {
    std::optional<Candidate> best;
    auto consider = [&](uint32_t u, uint32_t v) {
      if (m_.role[u] == SmoothRole::kFixed) return;
      Quadric q = m_.quadric[u];
      q += m_.quadric[v];
      Vec3d p = m_.pos[v];
      if (m_.role[u] == SmoothRole::kCurve) {
        if (!m_.junction_edge(u, v)) return;
        if (m_.role[v] == SmoothRole::kCurve) p = best_on_segment(q, m_.pos[u], m_.pos[v]);
      } else if (m_.role[v] == SmoothRole::kSheet) {
        p = best_free(q, m_.pos[u], m_.pos[v]);
      }
      const Candidate c{cost_mm(q, p), u, v, p, version_[u], version_[v]};
      if (!best || *best < c) best = c;  // the heap's first: least cost, then ids
    };
    if (m_.role[a] == SmoothRole::kSheet && m_.role[b] == SmoothRole::kSheet) {
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
    const ListPool::Lease around = m_.neighbours(v);
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
    m_.for_edge_triangles(u, v, [&](uint32_t t) {
      for (uint32_t m : m_.s.sides[t])
        if (m != 0 && budget_[m] > 0 && count_[m] > budget_[m]) over = true;
    });
    return over;
  }

  bool allowed(const Candidate& c) const {
    const uint32_t u = c.remove, v = c.keep;
    // Triangle counts: no part below the minimum.
    const ListPool::Lease removed_lease = m_.pool.take();
    std::vector<uint32_t>& removed = *removed_lease;
    m_.for_edge_triangles(u, v, [&](uint32_t t) { removed.push_back(t); });
    if (removed.empty()) return false;
    for (size_t m = 1; m < count_.size(); ++m) {
      int64_t lost = 0;
      for (uint32_t t : removed) lost += (m_.s.sides[t][0] == m) + (m_.s.sides[t][1] == m);
      if (lost > 0 && count_[m] - lost < kMinPartTriangles) return false;
    }
    // Link conditions: on the whole surface and in every part's shell.
    auto apexes = [&](uint32_t m, std::vector<uint32_t>& out) {
      for (uint32_t t : removed) {
        if (m != ~0u && m_.s.sides[t][0] != m && m_.s.sides[t][1] != m) continue;
        const uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
        for (int k = 0; k < 3; ++k)
          if (i[k] != u && i[k] != v) out.push_back(i[k]);
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
    };
    auto link_holds = [&](uint32_t m) {
      const ListPool::Lease nu = m_.neighbours(u, m), nv = m_.neighbours(v, m);
      if (nu->empty() || nv->empty()) return true;  // not both in this shell
      const ListPool::Lease common = m_.pool.take(), ap = m_.pool.take();
      std::set_intersection(nu->begin(), nu->end(), nv->begin(), nv->end(), std::back_inserter(*common));
      apexes(m, *ap);
      if (ap->empty()) return false;  // both in the shell, no edge of it between them
      return *common == *ap;
    };
    if (!link_holds(~0u)) return false;
    const ListPool::Lease materials_lease = m_.pool.take();
    std::vector<uint32_t>& materials = *materials_lease;
    for (uint32_t x : {u, v})
      for (uint32_t t : m_.tris[x])
        if (m_.alive_tri[t])
          for (uint32_t m : m_.s.sides[t])
            if (m != 0) materials.push_back(m);
    std::sort(materials.begin(), materials.end());
    materials.erase(std::unique(materials.begin(), materials.end()), materials.end());
    for (uint32_t m : materials)
      if (!link_holds(m)) return false;
    // A curve collapse must not close its curve into a loop of two edges.
    if (m_.role[u] == SmoothRole::kCurve) {
      const ListPool::Lease cu = m_.curve_neighbours(u), cv = m_.curve_neighbours(v);
      for (uint32_t w : *cu)
        if (w != v && std::find(cv->begin(), cv->end(), w) != cv->end()) return false;
    }
    // Geometry: no turned, degenerate or new sliver triangle.
    double worst_before = 1, worst_after = 1;
    for (uint32_t t : removed) worst_before = std::min(worst_before, m_.rho(t));
    for (uint32_t x : {u, v}) {
      for (uint32_t t : m_.tris[x]) {
        if (!m_.alive_tri[t] || (m_.has(t, u) && m_.has(t, v))) continue;
        const uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
        Vec3d p[3];
        for (int k = 0; k < 3; ++k) p[k] = i[k] == u || i[k] == v ? c.position : m_.pos[i[k]];
        const Vec3d n0 = cross(m_.pos[i[1]] - m_.pos[i[0]], m_.pos[i[2]] - m_.pos[i[0]]);
        const Vec3d n1 = cross(p[1] - p[0], p[2] - p[0]);
        const double l0 = norm(n0), l1 = norm(n1);
        if (!(l1 > 1e-12 * (l0 + 1e-30))) return false;
        if (dot(n0, n1) < kDecimationMaxTurnCos * l0 * l1) return false;
        worst_before = std::min(worst_before, m_.rho(t));
        worst_after = std::min(worst_after, radii_ratio(p[0], p[1], p[2]));
      }
    }
    if (worst_after < kSliver && worst_after < worst_before) return false;
    return true;
  }

  // Near where interfaces meet (the triangles within two rings of the edge are of more than one
  // interface), whether a triangle around the merged vertex would cross one of those triangles:
  // a sheet folded through another part's.
  bool crosses_nearby(const Candidate& c) const {
    const uint32_t u = c.remove, v = c.keep;
    // Sheet vertices all around: every triangle within two rings is of their one interface.
    const ListPool::Lease near_lease = m_.neighbours(u);
    std::vector<uint32_t>& near = *near_lease;
    {
      const ListPool::Lease nv = m_.neighbours(v);
      near.insert(near.end(), nv->begin(), nv->end());
    }
    if (std::all_of(near.begin(), near.end(), [&](uint32_t w) { return m_.role[w] == SmoothRole::kSheet; }))
      return false;
    const ListPool::Lease ring_lease = m_.pool.take();
    std::vector<uint32_t>& ring = *ring_lease;
    for (uint32_t w : near)
      for (uint32_t t : m_.tris[w])
        if (m_.alive_tri[t] && !(m_.has(t, u) && m_.has(t, v))) ring.push_back(t);
    std::sort(ring.begin(), ring.end());
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    bool mixed = false;
    for (uint32_t t : ring) mixed = mixed || !same_interface(m_.s.sides[t], m_.s.sides[ring[0]]);
    if (!mixed) return false;
    auto corner = [&](uint32_t i) { return i == u || i == v ? c.position : m_.pos[i]; };
    auto id = [&](uint32_t i) { return i == u ? v : i; };
    for (uint32_t f : ring) {
      const uint32_t* fi = &m_.s.mesh.indices[3 * size_t(f)];
      if (!m_.has(f, u) && !m_.has(f, v)) continue;  // not around the merged vertex
      const uint32_t fa = id(fi[0]), fb = id(fi[1]), fc = id(fi[2]);
      const Vec3d p[3] = {corner(fi[0]), corner(fi[1]), corner(fi[2])};
      for (uint32_t r : ring) {
        const uint32_t* ri = &m_.s.mesh.indices[3 * size_t(r)];
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

  void apply(const Candidate& c) {
    const uint32_t u = c.remove, v = c.keep;
    for (uint32_t t : m_.tris[u]) {
      if (!m_.alive_tri[t]) continue;
      uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
      if (m_.has(t, v)) {
        m_.alive_tri[t] = 0;
        for (uint32_t m : m_.s.sides[t])
          if (m != 0) --count_[m];
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (i[k] == u) i[k] = v;
      m_.tris[v].push_back(t);
    }
    std::vector<uint32_t>().swap(m_.tris[u]);
    m_.alive_vertex[u] = 0;
    ++version_[u];
    ++version_[v];
    m_.pos[v] = c.position;
    m_.quadric[v] += m_.quadric[u];
    m_.commit_witnesses();
    m_.junction_vertex[v] |= m_.junction_vertex[u];  // where the shell may touch itself, v now stands
    // Dead triangles leave the lists of the vertices around.
    {
      const ListPool::Lease around = m_.neighbours(v);
      for (uint32_t w : *around) m_.prune(w);
    }
    m_.prune(v);
    push_edges(v, false);
  }

  DecimationMesh m_;
  const DecimateOptions& options_;
  double limit_mm_ = 0;
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
  if (o.max_triangles > 0 && total > 0) {
    // Shares of the scene's budget by area, each at least the minimum a part keeps (rounded
    // down): the factor f found by bisection so that they add up to the budget at most. Plain
    // shares left small parts below the minimum, which they keep anyway, and the scene above its
    // budget (50 844 for 50 000 on a map of 54 parts).
    const auto shares = [&](double f, std::vector<int64_t>& b) {
      int64_t sum = 0;
      for (size_t p = 0; p < areas.size(); ++p) {
        b[p] = std::max<int64_t>(kMinPartTriangles, int64_t(std::floor(f * areas[p])));
        sum += b[p];
      }
      return sum;
    };
    double lo = 0, hi = double(o.max_triangles) / total;
    if (shares(hi, out) > o.max_triangles) {
      for (int k = 0; k < 64; ++k) {
        const double mid = 0.5 * (lo + hi);
        (shares(mid, out) <= o.max_triangles ? lo : hi) = mid;
      }
      shares(lo, out);  // every part at the minimum when even that is over the budget
    }
  }
  for (int64_t& b : out) {
    if (o.max_triangles_per_part > 0) {
      b = b > 0 ? std::min(b, o.max_triangles_per_part) : o.max_triangles_per_part;
    }
  }
  return out;
}

DecimationStats decimate_surface(LabelledSurface& surface, const DecimateOptions& options,
                                 std::span<const int64_t> budgets, int64_t surface_budget) {
  if (!options.active() || surface.sides.empty()) return {};
  return Collapser(surface, options, budgets, surface_budget).run();
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
