#include "segmesh/decimation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include "segmesh/detail/decimation_mesh.hpp"
#include "segmesh/detail/decimation_order.hpp"
#include "segmesh/detail/decimation_passes.hpp"
#include "segmesh/detail/quadric.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

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

// Parallel rounds (decimation.hpp): surfaces of fewer vertices go serial at once; a round takes
// the cheaper half of the vertices' best collapses (by cost bucket); budgets stop the rounds
// at this many times the budget, the cheapest-first loop going the rest; the rounds end when
// one makes fewer collapses than a 1/kRoundsEndShare of the live vertices (or kRoundsEndCount).
constexpr size_t kParallelMinVertices = 4096;
constexpr double kRoundShare = 0.5;
constexpr double kRoundsBudgetMargin = 1.5;
constexpr int64_t kRoundsEndShare = 256, kRoundsEndCount = 64;
constexpr double kSliver = 0.02;  // decimation.hpp says why not 0.05
// An octave of costs beyond the error bound keeps its order (detail/decimation_order.hpp) when
// this many times its candidates reach the triangles a budget still wants removed (a collapse
// removes up to four of the shells' triangles, and its pushes may add candidates to the
// octave): the budget may stop within it.
constexpr int64_t kExactOrderShare = 8;
// How far ahead of the loop's next candidate its prefetches go: the versions (read by the
// stale candidates' check), the vertices' data and lists' headers, the lists, the triangles
// the lists name, and their corners' positions.
constexpr size_t kPrefetchVersions = 8;
constexpr std::array<size_t, 4> kPrefetchAhead{3, 2, 1, 0};  // by DecimationMesh::prefetch stage
// Surfaces of fewer vertices keep buckets 4.4 % wide throughout: their data stays in cache.
constexpr size_t kSweepMinVertices = 65536;

class Collapser {
 public:
  Collapser(LabelledSurface& s, const DecimateOptions& options, std::span<const int64_t> budgets,
            int64_t surface_budget)
      : m_(s, options.error_mm > 0), options_(options), limit_mm_(options.error_mm * kWitnessShare) {
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
    DecimationStats stats;
    parallel_rounds(stats);
    for (uint32_t v = 0; v < m_.pos.size(); ++v)
      if (m_.alive_vertex[v]) push_edges(v, /*higher_only=*/true);
    // A vertex dies only in a collapse, which steps its version: the versions say it all.
    auto current = [&](const Candidate& c) {
      return version_[c.remove] == c.remove_version && version_[c.keep] == c.keep_version;
    };
    // The order within an octave of costs is kept where a budget may stop in it, and on a
    // surface small enough for the cache, where sweeps gain nothing.
    const bool small = m_.pos.size() < kSweepMinVertices;
    auto exact = [&](double upper_cost, size_t count) {
      if (small) return true;
      if (!has_budget_ || (limit_mm_ > 0 && upper_cost <= limit_mm_)) return false;
      return kExactOrderShare * int64_t(count) >= triangles_over_budget();
    };
    Candidate c;
    auto ahead = [&](const Candidate& c) {
      __builtin_prefetch(&version_[c.remove]);
      __builtin_prefetch(&version_[c.keep]);
    };
    while (queue_.pop(c, current, exact, ahead)) {
      // The loop waits on memory: the next candidates' data is asked for ahead.
      if (const Candidate* n = queue_.peek(kPrefetchVersions)) ahead(*n);
      for (int stage = 0; stage < int(kPrefetchAhead.size()); ++stage)
        if (const Candidate* n = queue_.peek(kPrefetchAhead[size_t(stage)])) {
          m_.prefetch(stage, n->remove);
          m_.prefetch(stage, n->keep);
        }
      if (!current(c)) continue;
      const bool within_error = limit_mm_ > 0 && c.cost <= limit_mm_;
      if (!within_error && !has_budget_) continue;  // never pushed (push_edges)
      if (!within_error && !removes_from_part_over_budget(c.remove, c.keep)) continue;
      if (!allowed(c)) continue;
      // Beyond the error bound (a budget's collapse) the witnesses are only kept alive.
      if (!m_.collapse_keeps_witnesses(c.remove, c.keep, c.position,
                                       within_error ? limit_mm_ * limit_mm_ : kInfinity))
        continue;
      if (m_.crosses_nearby(c.remove, c.keep, c.position)) continue;
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
            m_.crosses_nearby(c->remove, c->keep, c->position))
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

  void push_edges(uint32_t v, bool higher_only) {
    const ListPool::Lease around = m_.neighbours(v);
    for (uint32_t w : *around) {  // all asked for at once, not a miss at a time
      __builtin_prefetch(&m_.quadric[w]);
      __builtin_prefetch(reinterpret_cast<const char*>(&m_.quadric[w]) + 64);
      __builtin_prefetch(&m_.pos[w]);
      __builtin_prefetch(&m_.role[w]);
      __builtin_prefetch(&version_[w]);
    }
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

  // Whether a triangle around u or v had a radii ratio at or below `worst`.
  bool had_as_bad(uint32_t u, uint32_t v, const std::vector<uint32_t>& removed,
                  double worst) const {
    for (uint32_t t : removed)
      if (m_.rho(t) <= worst) return true;
    for (uint32_t x : {u, v})
      for (uint32_t t : m_.tris[x])
        if (m_.kept_by_collapse(t, u, v) && m_.rho(t) <= worst) return true;
    return false;
  }

  bool allowed(const Candidate& c) const {
    const uint32_t u = c.remove, v = c.keep;
    // Triangle counts: no part below the minimum.
    const ListPool::Lease removed_lease = m_.pool().take();
    std::vector<uint32_t>& removed = *removed_lease;
    m_.for_edge_triangles(u, v, [&](uint32_t t) { removed.push_back(t); });
    if (removed.empty()) return false;
    for (uint32_t r : removed)
      for (uint32_t m : m_.s.sides[r]) {
        if (m == 0) continue;
        int64_t lost = 0;
        for (uint32_t t : removed) lost += (m_.s.sides[t][0] == m) + (m_.s.sides[t][1] == m);
        if (count_[m] - lost < kMinPartTriangles) return false;
      }
    // Geometry: no turned, degenerate or new sliver triangle. Before the link checks: most
    // refusals are new slivers (421 000 of 454 000 on the phantom at 0.2 mm), and these are cheap.
    double worst_after = 1;
    for (uint32_t x : {u, v}) {
      for (uint32_t t : m_.tris[x]) {
        if (!m_.kept_by_collapse(t, u, v)) continue;
        const uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
        Vec3d p[3];
        for (int k = 0; k < 3; ++k) p[k] = i[k] == u || i[k] == v ? c.position : m_.pos[i[k]];
        const Vec3d n0 = cross(m_.pos[i[1]] - m_.pos[i[0]], m_.pos[i[2]] - m_.pos[i[0]]);
        const Vec3d n1 = cross(p[1] - p[0], p[2] - p[0]);
        const double l0 = norm(n0), l1 = norm(n1);
        if (!(l1 > 1e-12 * (l0 + 1e-30))) return false;
        if (dot(n0, n1) < kDecimationMaxTurnCos * l0 * l1) return false;
        worst_after = std::min(worst_after, radii_ratio(p[0], p[1], p[2]));
      }
    }
    // A new sliver is refused unless one as bad was there before (the neighbourhood measured
    // only then: most collapses make none).
    if (worst_after < kSliver && !had_as_bad(u, v, removed, worst_after)) return false;
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
      const ListPool::Lease common = m_.pool().take(), ap = m_.pool().take();
      std::set_intersection(nu->begin(), nu->end(), nv->begin(), nv->end(), std::back_inserter(*common));
      apexes(m, *ap);
      if (ap->empty()) return false;  // both in the shell, no edge of it between them
      return *common == *ap;
    };
    if (!link_holds(~0u)) return false;
    const ListPool::Lease materials_lease = m_.pool().take();
    std::vector<uint32_t>& materials = *materials_lease;
    size_t around = 0;  // triangles around u and v (those on the edge twice)
    for (uint32_t x : {u, v})
      for (uint32_t t : m_.tris[x])
        if (m_.alive_tri[t]) {
          ++around;
          const std::array<uint32_t, 2>& sides = m_.s.sides[t];
          if (sides[0] != 0) materials.push_back(sides[0]);
          if (sides[1] != 0 && sides[1] != sides[0]) materials.push_back(sides[1]);
        }
    std::sort(materials.begin(), materials.end());
    // A material on every triangle around u and v (both of a sheet's, an independent part's)
    // has the whole surface's link, checked above.
    for (size_t k = 0; k < materials.size();) {
      size_t end = k;
      while (end < materials.size() && materials[end] == materials[k]) ++end;
      if (end - k != around && !link_holds(materials[k])) return false;
      k = end;
    }
    // A curve collapse must not close its curve into a loop of two edges.
    if (m_.role[u] == SmoothRole::kCurve) {
      const ListPool::Lease cu = m_.curve_neighbours(u), cv = m_.curve_neighbours(v);
      for (uint32_t w : *cu)
        if (w != v && std::find(cv->begin(), cv->end(), w) != cv->end()) return false;
    }
    return true;
  }

  void apply(const Candidate& c) {
    m_.for_edge_triangles(c.remove, c.keep, [&](uint32_t t) {
      for (uint32_t m : m_.s.sides[t])
        if (m != 0) --count_[m];
    });
    collapse(c);
    push_edges(c.keep, false);
  }

  // The collapse itself, checked: triangles, position, quadric, witnesses, the lists of the
  // vertices around. Touches only u, v, their neighbours and the triangles around those
  // (the parallel rounds rely on it); the caller counts the removed triangles.
  void collapse(const Candidate& c) {
    const uint32_t u = c.remove, v = c.keep;
    // The triangles on the edge die; their third corners (and v) hold them in their lists.
    const ListPool::Lease apexes_lease = m_.pool().take();
    std::vector<uint32_t>& apexes = *apexes_lease;
    m_.tris.reserve(v, uint32_t(m_.tris[u].size()));  // no list moves in the loop
    for (uint32_t t : m_.tris[u]) {
      if (!m_.alive_tri[t]) continue;
      uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
      if (m_.has(t, v)) {
        m_.alive_tri[t] = 0;
        for (int k = 0; k < 3; ++k)
          if (i[k] != u && i[k] != v) apexes.push_back(i[k]);
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (i[k] == u) i[k] = v;
      m_.tris.push_back(v, t);
    }
    m_.tris.clear(u);
    m_.alive_vertex[u] = 0;
    ++version_[u];
    ++version_[v];
    m_.pos[v] = c.position;
    m_.quadric[v] += m_.quadric[u];
    m_.commit_witnesses();
    m_.junction_vertex[v] |= m_.junction_vertex[u];  // where the shell may touch itself, v now stands
    // Dead triangles leave the lists of the vertices that held them.
    for (uint32_t w : apexes) m_.prune(w);
    m_.prune(v);
  }

  bool admissible(const Candidate& c) const { return has_budget_ || c.cost <= limit_mm_; }

  // Rounds of collapses in parallel before the cheapest-first loop (decimation.hpp). Every
  // vertex keeps its best admissible collapse, made again only when a collapse changed its
  // neighbourhood (or refused: until then). A round takes the cheaper half of them by cost
  // bucket, in bucket order (ties by vertex id), each unless its region (the two vertices and
  // their neighbours) meets one taken before, so no two taken collapses read or write the same
  // vertex, triangle list or witness list; then checks and makes them on all threads. The
  // triangle counts are reserved when a collapse is taken, so no part falls below its minimum
  // (or, beyond the error bound, below kRoundsBudgetMargin times a budget) whatever is refused.
  // Deterministic: the order is fixed before the parallel part.
  void parallel_rounds(DecimationStats& stats) {
    const size_t nv = m_.pos.size();
    if (!options_.parallel_rounds || nv < kParallelMinVertices || !(limit_mm_ > 0 || has_budget_))
      return;
    enum : uint8_t { kDirty, kHas, kNone };
    std::vector<Candidate> best(nv);
    std::vector<uint8_t> state(nv, kDirty);
    std::vector<uint32_t> refused(nv, ~0u);  // the neighbour of a refused best, skipped
    std::vector<uint16_t> bucket(nv);  // best's cost bucket: the scans below stay in cache
    auto keep_better = [&](uint32_t x, const std::optional<Candidate>& c) {
      if (c && admissible(*c) && (state[x] != kHas || best[x] < *c)) {
        best[x] = *c;
        bucket[x] = uint16_t(CostBuckets::bucket(c->cost));
        state[x] = kHas;
      }
    };
    std::vector<uint32_t> mark(nv, 0), order, histogram(CostBuckets::bucket_count());
    std::vector<Candidate> taken;
    std::vector<uint32_t> owner, lost_start, lost;  // per taken: its owner, its edge's triangles
    std::vector<char> made;
    std::vector<int64_t> reserved(count_.size());
    const ListPool::Lease region_lease = m_.pool().take();
    std::vector<uint32_t>& region = *region_lease;
    std::vector<uint32_t> live_ids(nv);  // the live vertices, ascending: the scans' range
    std::iota(live_ids.begin(), live_ids.end(), 0u);
    for (uint32_t round = 1;; ++round) {
      tbb::this_task_arena::isolate([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, live_ids.size(), 2048), [&](const auto& r) {
          for (size_t i = r.begin(); i < r.end(); ++i) {
            const uint32_t x = live_ids[i];
            if (state[x] != kDirty) continue;
            state[x] = kNone;
            if (!m_.alive_vertex[x]) continue;
            const ListPool::Lease around = m_.neighbours(x);
            for (uint32_t w : *around)
              if (w != refused[x]) keep_better(x, candidate(x, w));
          }
        });
      });
      // The cheaper kRoundShare of the candidates (whole buckets; at least the cheapest bucket),
      // in vertex order: neighbours in memory, and cheaper than cost order by a fifth.
      std::fill(histogram.begin(), histogram.end(), 0);
      size_t total = 0;
      for (uint32_t x : live_ids)
        if (state[x] == kHas) {
          ++histogram[bucket[x]];
          ++total;
        }
      if (total == 0) break;
      size_t cut_bucket = 0;
      for (size_t b = 0, sum = 0, found = 0; b < histogram.size(); ++b) {
        if (histogram[b] == 0) continue;
        sum += histogram[b];
        if (found && sum > size_t(kRoundShare * double(total))) break;
        cut_bucket = b;
        found = 1;
      }
      order.clear();
      for (uint32_t x : live_ids)
        if (state[x] == kHas && bucket[x] <= cut_bucket) order.push_back(x);
      // Take them in order, each where no region taken before reaches.
      taken.clear();
      owner.clear();
      lost.clear();
      lost_start.assign(1, 0);
      std::fill(reserved.begin(), reserved.end(), 0);
      int64_t reserved_all = 0;
      const int64_t shells = shell_triangles();
      for (uint32_t x : order) {
        const Candidate& c = best[x];
        // Marked: the regions taken and their neighbours, so the regions meet iff u or v is.
        if (mark[c.remove] == round || mark[c.keep] == round) continue;
        const size_t first_lost = lost.size();
        m_.for_edge_triangles(c.remove, c.keep, [&](uint32_t t) { lost.push_back(t); });
        const bool within_error = limit_mm_ > 0 && c.cost <= limit_mm_;
        bool fits = true;
        int64_t lost_all = 0;
        for (size_t k = first_lost; k < lost.size(); ++k)
          for (uint32_t m : m_.s.sides[lost[k]])
            if (m != 0) {
              reserved[m] += 1;
              lost_all += 1;
            }
        for (size_t k = first_lost; k < lost.size(); ++k)
          for (uint32_t m : m_.s.sides[lost[k]]) {
            const int64_t left = count_[m] - reserved[m];
            if (m != 0 && (left < kMinPartTriangles ||
                           (!within_error && budget_[m] > 0 &&
                            double(left) < kRoundsBudgetMargin * double(budget_[m]))))
              fits = false;
          }
        if (!within_error && surface_budget_ > 0 &&
            double(shells - reserved_all - lost_all) < kRoundsBudgetMargin * double(surface_budget_))
          fits = false;
        if (!fits) {
          for (size_t k = first_lost; k < lost.size(); ++k)
            for (uint32_t m : m_.s.sides[lost[k]])
              if (m != 0) reserved[m] -= 1;
          lost.resize(first_lost);
          continue;
        }
        reserved_all += lost_all;
        region.clear();
        for (uint32_t y : {c.remove, c.keep})
          for (uint32_t t : m_.tris[y])
            if (m_.alive_tri[t])
              for (int k = 0; k < 3; ++k) region.push_back(m_.s.mesh.indices[3 * size_t(t) + size_t(k)]);
        std::sort(region.begin(), region.end());
        region.erase(std::unique(region.begin(), region.end()), region.end());
        for (uint32_t w : region)
          for (uint32_t t : m_.tris[w])
            if (m_.alive_tri[t])
              for (int k = 0; k < 3; ++k) mark[m_.s.mesh.indices[3 * size_t(t) + size_t(k)]] = round;
        // The collapse adds u's triangles to v's list: room made here, as lists move only
        // when no other thread reads them.
        m_.tris.reserve(c.keep, uint32_t(m_.tris[c.remove].size()));
        taken.push_back(c);
        owner.push_back(x);
        lost_start.push_back(uint32_t(lost.size()));
      }
      // Check and make them on all threads.
      made.assign(taken.size(), 0);
      tbb::this_task_arena::isolate([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, taken.size(), 16), [&](const auto& r) {
          for (size_t k = r.begin(); k < r.end(); ++k) {
            const Candidate& c = taken[k];
            const bool within_error = limit_mm_ > 0 && c.cost <= limit_mm_;
            if (!allowed(c) ||
                !m_.collapse_keeps_witnesses(c.remove, c.keep, c.position,
                                             within_error ? limit_mm_ * limit_mm_ : kInfinity,
                                             /*far_ring=*/false) ||
                m_.crosses_nearby(c.remove, c.keep, c.position)) {
              // Refused: the next best edge next round, then none until a collapse nearby.
              const uint32_t x = owner[k];
              const bool first = refused[x] == ~0u;
              refused[x] = x == c.remove ? c.keep : c.remove;
              state[x] = first ? kDirty : kNone;
              continue;
            }
            collapse(c);
            state[c.remove] = kNone;  // gone
            state[c.keep] = kDirty;
            refused[c.keep] = ~0u;
            // A neighbour whose best collapse is not along (u, v)'s edges keeps it unless its
            // edge to v is now better; the others are made again next round.
            const ListPool::Lease around = m_.neighbours(c.keep);
            for (uint32_t w : *around) {
              const Candidate& b = best[w];
              if (state[w] == kHas && b.remove != c.remove && b.keep != c.remove &&
                  b.remove != c.keep && b.keep != c.keep)
                keep_better(w, candidate(w, c.keep));
              else
                state[w] = kDirty;
              refused[w] = ~0u;
            }
            made[k] = 1;
          }
        });
      });
      int64_t count = 0;
      for (size_t k = 0; k < taken.size(); ++k) {
        if (!made[k]) continue;
        for (uint32_t i = lost_start[k]; i < lost_start[k + 1]; ++i)
          for (uint32_t m : m_.s.sides[lost[i]])
            if (m != 0) --count_[m];
        ++count;
        stats.largest_cost_mm = std::max(stats.largest_cost_mm, taken[k].cost);
      }
      stats.collapses += count;
      std::erase_if(live_ids, [&](uint32_t x) { return !m_.alive_vertex[x]; });
      if (count < std::max(kRoundsEndCount, int64_t(live_ids.size()) / kRoundsEndShare)) break;
    }
  }

  DecimationMesh m_;
  const DecimateOptions& options_;
  double limit_mm_ = 0;
  std::vector<uint32_t> version_;
  std::vector<int64_t> count_, budget_;  // by material
  int64_t surface_budget_ = 0;           // for the shells' triangles together
  bool has_budget_ = false;

  // The fewest triangles a budget still wants removed: of the shells (the surface's budget) or
  // of a part over its own; 0 when all are within.
  int64_t triangles_over_budget() const {
    int64_t least = std::numeric_limits<int64_t>::max();
    if (surface_budget_ > 0) least = std::max<int64_t>(0, shell_triangles() - surface_budget_);
    for (size_t m = 1; m < count_.size(); ++m)
      if (budget_[m] > 0) least = std::min(least, std::max<int64_t>(0, count_[m] - budget_[m]));
    return least == std::numeric_limits<int64_t>::max() ? 0 : least;
  }

  int64_t shell_triangles() const { return std::accumulate(count_.begin() + 1, count_.end(), int64_t{0}); }
  CostBuckets queue_;
};


}  // namespace

DecimationStats decimate_surface(LabelledSurface& surface, const DecimateOptions& options,
                                 std::span<const int64_t> budgets, int64_t surface_budget) {
  if (!options.active() || surface.sides.empty()) return {};
  return Collapser(surface, options, budgets, surface_budget).run();
}

}  // namespace segmesh
