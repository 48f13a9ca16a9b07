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

#include "segmesh/detail/decimation_blocks.hpp"
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

// The block phase (decimation.hpp): blocks of about this many vertices (cubes of a grid sized by
// the surface's area); surfaces of fewer than two blocks' vertices go to the loop at once.
constexpr size_t kBlockVertices = 16384;
// With a budget, the blocks collapse beyond the error bound until the triangles they can remove
// are at most kBlockBudgetStop times their share of the budget, each round letting every block
// remove its share of those above kBlockBudgetTarget times it; the loop removes the rest
// cheapest first over the whole surface.
constexpr double kBlockBudgetStop = 1.5, kBlockBudgetTarget = 1.25;
// The blocks' triangle counts by material are one dense table: no block phase beyond this many
// entries (blocks times parts).
constexpr size_t kBlockCountsMax = size_t(1) << 22;
// Room for the triangle lists that move in the block phase, a share of the lists' entries.
constexpr double kBlockListRoom = 0.5;
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

// Where a loop of collapses works: the whole surface (the cheapest-first loop), or one block of
// the block phase, with its own queue, the counts by material of the triangles it owns (every
// corner its own: the only ones it can remove), and what it may remove beyond the error bound in
// the current round.
struct Region {
  static constexpr uint32_t kWhole = ~0u;
  uint32_t id = kWhole;
  CostBuckets queue;
  int64_t* count = nullptr;        // by material
  int64_t units = 0;               // block: its triangles' shell sides (its counts together)
  int64_t locked = 0;              // block: those of them this phase cannot remove
  int64_t allowance = 0;           // block: shell sides it may remove beyond the error bound
  bool stopped = false;            // block: the allowance ended its round
  std::vector<uint32_t> lost;      // block: the material of every shell side removed this round
  std::vector<uint32_t> vertices;  // block: its core vertices, ascending
  VertexTriangles::Room room;      // block: for its moved triangle lists
  DecimationStats stats;
};

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
    whole_.count = count_.data();
  }

  DecimationStats run() {
    DecimationStats stats;
    // Twice: the second grid shifted by half a block, so the first one's borders are inside
    // its blocks.
    const bool blocks = options_.blocks == DecimateOptions::Blocks::kOn &&
                        m_.pos.size() >= 2 * kBlockVertices && (limit_mm_ > 0 || has_budget_);
    if (const double side = blocks ? decimation_block_side(m_, kBlockVertices) : 0; side > 0) {
      const size_t reached = block_phase(stats, side, 0.0, CostBuckets::bucket_count());
      block_phase(stats, side, 0.5, reached);
    }
    for (uint32_t v = 0; v < m_.pos.size(); ++v)
      if (m_.alive_vertex[v]) push_edges(v, /*higher_only=*/true, whole_);
    collapse_loop(whole_, std::numeric_limits<size_t>::max());
    stats.collapses += whole_.stats.collapses;
    stats.largest_cost_mm = std::max(stats.largest_cost_mm, whole_.stats.largest_cost_mm);
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
        if (!c || c->cost > bound || !allowed(*c, count_.data()) ||
            !m_.collapse_keeps_witnesses(c->remove, c->keep, c->position, limit2) ||
            m_.crosses_nearby(c->remove, c->keep, c->position))
          continue;
        apply(*c, whole_);
        ++made;
        break;
      }
    }
    return made;
  }

 private:
  // Collapses from r's queue, cheapest first, through cost bucket `through`.
  void collapse_loop(Region& r, size_t through) {
    const bool whole = r.id == Region::kWhole;
    // A vertex dies only in a collapse, which steps its version: the versions say it all.
    auto current = [&](const Candidate& c) {
      return version_[c.remove] == c.remove_version && version_[c.keep] == c.keep_version;
    };
    // The order within an octave of costs is kept where a budget may stop in it, on a surface
    // small enough for the cache, where sweeps gain nothing, and in the blocks, whose rounds go
    // bucket by bucket.
    const bool small = m_.pos.size() < kSweepMinVertices;
    auto exact = [&](double upper_cost, size_t count) {
      if (small || !whole) return true;
      if (!has_budget_ || (limit_mm_ > 0 && upper_cost <= limit_mm_)) return false;
      return kExactOrderShare * int64_t(count) >= triangles_over_budget();
    };
    Candidate c;
    auto ahead = [&](const Candidate& c) {
      __builtin_prefetch(&version_[c.remove]);
      __builtin_prefetch(&version_[c.keep]);
    };
    while (r.queue.pop(c, current, exact, ahead, through)) {
      // The loop waits on memory: the next candidates' data is asked for ahead.
      if (const Candidate* n = r.queue.peek(kPrefetchVersions)) ahead(*n);
      for (int stage = 0; stage < int(kPrefetchAhead.size()); ++stage)
        if (const Candidate* n = r.queue.peek(kPrefetchAhead[size_t(stage)])) {
          m_.prefetch(stage, n->remove);
          m_.prefetch(stage, n->keep);
        }
      if (!current(c)) continue;
      const bool within_error = limit_mm_ > 0 && c.cost <= limit_mm_;
      if (!within_error && !has_budget_) continue;  // never pushed (push_edges)
      int64_t units = 0;
      if (whole) {
        if (!within_error && !removes_from_part_over_budget(c.remove, c.keep)) continue;
      } else {
        if (!in_block_core(m_, core_, c.remove, c.keep, r.id)) continue;
        if (!within_error) {
          if (!block_budget_) continue;  // left for the loop over the whole surface
          m_.for_edge_triangles(c.remove, c.keep, [&](uint32_t t) {
            for (uint32_t m : m_.s.sides[t]) units += m != 0;
          });
          if (units > r.allowance) {  // this round's share is used up
            r.queue.push(c);
            r.stopped = true;
            break;
          }
        }
      }
      if (!allowed(c, r.count)) continue;
      // Beyond the error bound (a budget's collapse) the witnesses are only kept alive.
      if (!m_.collapse_keeps_witnesses(c.remove, c.keep, c.position,
                                       within_error ? limit_mm_ * limit_mm_ : kInfinity))
        continue;
      if (m_.crosses_nearby(c.remove, c.keep, c.position)) continue;
      if (!whole && !m_.tris.try_room(c.keep, merged_size(c.remove, c.keep), r.room)) continue;
      r.allowance -= units;
      apply(c, r);
      ++r.stats.collapses;
      r.stats.largest_cost_mm = std::max(r.stats.largest_cost_mm, c.cost);
    }
  }

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

  // The candidates of v's edges into r's queue (in a block, only edges to its core vertices).
  void push_edges(uint32_t v, bool higher_only, Region& r) {
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
      if (r.id != Region::kWhole && core_[w] != r.id) continue;
      const auto c = candidate(v, w);
      // Without a budget a collapse above the error bound is never made: not worth a heap entry.
      if (c && (has_budget_ || c->cost <= limit_mm_)) r.queue.push(*c);
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

  // `count`: the triangles by material that no part may drop below the minimum of (the whole
  // surface's, or a block's own).
  bool allowed(const Candidate& c, const int64_t* count) const {
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
        if (count[m] - lost < kMinPartTriangles) return false;
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

  void apply(const Candidate& c, Region& r) {
    m_.for_edge_triangles(c.remove, c.keep, [&](uint32_t t) {
      for (uint32_t m : m_.s.sides[t])
        if (m != 0) {
          --r.count[m];
          if (r.id != Region::kWhole) {
            --r.units;
            r.lost.push_back(m);
          }
        }
    });
    collapse(c);
    push_edges(c.keep, false, r);
  }

  // The collapse itself, checked: triangles, position, quadric, witnesses, the lists of the
  // vertices around. Touches only u, v, their neighbours and the triangles around those (the
  // block phase relies on it); the caller counts the removed triangles.
  void collapse(const Candidate& c) {
    const uint32_t u = c.remove, v = c.keep;
    // The triangles on the edge die; their third corners (and v) hold them in their lists.
    const ListPool::Lease apexes_lease = m_.pool().take();
    std::vector<uint32_t>& apexes = *apexes_lease;
    uint32_t moving = 0;
    for (uint32_t t : m_.tris[u]) {
      if (!m_.alive_tri[t]) continue;
      if (!m_.has(t, v)) {
        ++moving;
        continue;
      }
      m_.alive_tri[t] = 0;
      const uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
      for (int k = 0; k < 3; ++k)
        if (i[k] != u && i[k] != v) apexes.push_back(i[k]);
    }
    // v's list drops its dead triangles (the edge's among them) before it takes u's others, so
    // the merged list mostly fits where v's is (in the block phase the caller made the room).
    m_.prune(v);
    m_.tris.reserve(v, moving);
    for (uint32_t t : m_.tris[u]) {
      if (!m_.alive_tri[t]) continue;
      uint32_t* i = &m_.s.mesh.indices[3 * size_t(t)];
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
  }

  // The size of v's triangle list after the collapse of u into v.
  uint32_t merged_size(uint32_t u, uint32_t v) const {
    uint32_t n = 0;
    for (uint32_t x : {u, v})
      for (uint32_t t : m_.tris[x]) n += m_.kept_by_collapse(t, u, v);
    return n;
  }

  // The block phase before the cheapest-first loop over the whole surface (decimation.hpp):
  // blocks of space collapse their own cores side by side, each cheapest first; with a budget,
  // in rounds of one cost bucket at a time, so the blocks reach each cost together.
  // Cubes of `side` millimetres, the grid shifted by `shift` sides. Returns the last cost bucket
  // it collapsed beyond the error bound in. With a `cap` (a bucket; bucket_count(): none), it
  // collapses beyond the bound only up to that bucket.
  size_t block_phase(DecimationStats& stats, double side, double shift, size_t cap) {
    const size_t nv = m_.pos.size(), materials = count_.size();
    DecimationBlocks blocks = decimation_blocks(m_, side, shift, materials, kBlockCountsMax);
    if (blocks.count == 0) return 0;
    core_ = std::move(blocks.core);
    block_count_ = std::move(blocks.sides);
    std::vector<Region> regions(blocks.count);
    for (uint32_t b = 0; b < blocks.count; ++b) {
      Region& r = regions[b];
      r.id = b;
      r.count = &block_count_[size_t(b) * materials];
      r.units = std::accumulate(r.count, r.count + materials, int64_t{0});
      r.locked = blocks.locked[b];
      r.vertices = std::move(blocks.vertices[b]);
    }
    // With one budget for the whole surface (the shells' or a single part's), the blocks may
    // collapse beyond the error bound too.
    const bool single_part = count_.size() == 2;
    const int64_t budget = surface_budget_ > 0 ? surface_budget_ : single_part ? budget_[1] : 0;
    const bool other_budgets = !single_part && std::any_of(budget_.begin(), budget_.end(),
                                                           [](int64_t b) { return b > 0; });
    block_budget_ = budget > 0 && !other_budgets;
    auto units = [&] { return surface_budget_ > 0 ? shell_triangles() : count_[1]; };
    const size_t error_bucket = limit_mm_ > 0 ? CostBuckets::bucket(limit_mm_) : 0;
    const size_t none = CostBuckets::bucket_count();
    {
      // Room for moved lists, by the blocks' core vertices.
      const double room =
          kBlockListRoom * double(m_.tris.entries()) / double(std::max<size_t>(1, nv));
      for (Region& r : regions)
        r.room = m_.tris.take_room(size_t(room * double(r.vertices.size())));
    }
    auto each_block = [&](auto&& f) {
      tbb::this_task_arena::isolate([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, regions.size(), 1), [&](const auto& range) {
          for (size_t b = range.begin(); b < range.end(); ++b) f(regions[b]);
        });
      });
    };
    each_block([&](Region& r) {
      for (uint32_t v : r.vertices) push_edges(v, /*higher_only=*/true, r);
    });
    // The blocks' triangles they can remove.
    auto removable = [](const Region& r) { return std::max<int64_t>(0, r.units - r.locked); };
    auto owned = [&] {
      return std::accumulate(regions.begin(), regions.end(), int64_t{0},
                             [&](int64_t a, const Region& r) { return a + removable(r); });
    };
    // Their share of the budget: what they are of all triangles (the rest, near the borders
    // between blocks, stays as it is in this phase).
    const double owned_budget =
        double(budget) * double(owned()) / double(std::max<int64_t>(1, units()));
    const int64_t unlimited = std::numeric_limits<int64_t>::max() / 2;
    size_t reached = 0;
    for (;;) {
      size_t next = none;
      for (const Region& r : regions) next = std::min(next, r.queue.next_bucket());
      if (next == none) break;
      // Beyond the error bound: the first grid while the blocks' triangles are above
      // kBlockBudgetStop times their share, the second up to the cost the first reached.
      int64_t over = 0;
      if (block_budget_ && cap == none && double(owned()) > kBlockBudgetStop * owned_budget)
        over = owned() - int64_t(std::ceil(kBlockBudgetTarget * owned_budget));
      if (block_budget_ && cap != none && next <= cap) over = unlimited;
      size_t through = next;
      if (over <= 0) {
        // Within the error bound only: every block to the end of it in one round.
        if (!(limit_mm_ > 0) || next > error_bucket) break;
        through = error_bucket;
      } else {
        reached = through;
      }
      const int64_t all = owned();
      bool stopped = false;
      for (Region& r : regions) {
        r.allowance = over == unlimited ? unlimited
                      : over > 0 && all > 0
                          ? int64_t(double(over) * double(removable(r)) / double(all))
                          : 0;
        r.stopped = false;
      }
      const int64_t before =
          std::accumulate(regions.begin(), regions.end(), int64_t{0},
                          [](int64_t a, const Region& r) { return a + r.stats.collapses; });
      each_block([&](Region& r) { collapse_loop(r, through); });
      int64_t after = 0;
      for (Region& r : regions) {
        for (uint32_t m : r.lost) --count_[m];
        r.lost.clear();
        after += r.stats.collapses;
        stopped = stopped || r.stopped;
      }
      if (after == before && stopped) break;  // shares too small to take a collapse
    }
    for (const Region& r : regions) {
      stats.collapses += r.stats.collapses;
      stats.largest_cost_mm = std::max(stats.largest_cost_mm, r.stats.largest_cost_mm);
    }
    block_budget_ = false;
    core_ = {};
    block_count_ = {};
    return reached;
  }

  DecimationMesh m_;
  const DecimateOptions& options_;
  double limit_mm_ = 0;
  std::vector<uint32_t> version_;
  std::vector<int64_t> count_, budget_;  // by material
  int64_t surface_budget_ = 0;           // for the shells' triangles together
  bool has_budget_ = false;
  // The block phase: each vertex's block when it is a core vertex (else
  // DecimationBlocks::kBorder), the blocks' triangle counts by material, and whether blocks
  // collapse beyond the error bound.
  std::vector<uint32_t> core_;
  std::vector<int64_t> block_count_;
  bool block_budget_ = false;

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
  Region whole_;
};


}  // namespace

DecimationStats decimate_surface(LabelledSurface& surface, const DecimateOptions& options,
                                 std::span<const int64_t> budgets, int64_t surface_budget) {
  if (!options.active() || surface.sides.empty()) return {};
  return Collapser(surface, options, budgets, surface_budget).run();
}

}  // namespace segmesh
