// The smoothing filters (smoothing.hpp) on one mesh: Laplacian steps (Laplacian and Taubin), HC
// and the windowed sinc, each as sweeps over the triangles and passes over the vertices
// (smoothing_sweeps.hpp) in buffers of four floats per vertex (float4.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "segmesh/detail/float4.hpp"
#include "segmesh/detail/smoothing_sweeps.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {

// The filters, on displacements D from the original positions o (the mesh's): the smoothed
// position is o + D, so the state stays small (a fraction of a voxel, at most a few millimetres
// for the sinc's intermediate terms) and float keeps it to ~1e-7 of its size. Each sweep is one
// pass over the triangles, adding every triangle's terms to its three corners (a scatter,
// triangle_scatter.hpp), into an accumulator buffer, then one pass over the vertices. Over a
// vertex's c triangles each neighbour is met twice on a closed mesh, so a sum S(x)_i of x_j over
// the other two corners of i's triangles is 2 c_i avg_j x_j. Sums that a vertex pass needs next
// to its own old value are made ready by the pass before (the accumulator is preset with the
// rest of the update, scaled by 2 c_i), so every filter runs in two buffers (three for the sinc).
// The count c_i rides in the fourth lane of a buffer that the sweep does not add into.
//
// Joint smoothing of a surface shared by several parts (joint_smoothing.hpp) changes whose
// neighbours a vertex averages, nothing else: a sheet vertex (kSheet) averages over its
// triangles as above, a vertex on a junction curve (kCurve) over its two neighbours along the
// curve only, each curve edge counting as one triangle (its neighbour twice), and a fixed vertex
// (kFixed: where curves meet or end) has no neighbours, so it stays where it is. The sweeps add
// every triangle's terms to all its corners, as on a single mesh, and put the few pinned
// (curve and fixed) vertices' accumulators back afterwards: no per-corner test in the sweep.
enum class SmoothRole : uint8_t { kSheet, kCurve, kFixed };
struct SmoothTopology {
  std::vector<SmoothRole> role;                      // per vertex
  std::vector<std::array<uint32_t, 2>> curve_edges;  // the edges of the junction curves
  std::vector<uint32_t> pinned;                      // the vertices that are not kSheet
};

class Smoother {
 public:
  Smoother(const Triangles& triangles, const Vec3f* original, size_t n, Ticker& ticker,
           const SmoothTopology* topology = nullptr)
      : t_(triangles),
        o_(original),
        n_(n),
        ticker_(ticker),
        topology_(topology),
        plan_(finish_plan(triangles.chunks, n)) {}

  // Laplacian steps p' = p + f L(p), one per factor: D' = D + f L(o + D). `per_tick` factors
  // make one iteration. d holds D and the counts, scratch is zero; afterwards the same.
  void laplacian(const std::vector<double>& factors, size_t per_tick, F4*& d, F4*& scratch);

  // HC, simultaneous version (header). With q = o + D the previous positions:
  //   b_i = avg q_j - (alpha o_i + (1 - alpha) q_i) = L0_i + avg D_j - keep D_i
  //   D'_i = spread (b_i - avg b_j) + keep D_i
  // (keep = 1 - alpha, spread = 1 - beta)
  // with L0 = L(o). Two sweeps per iteration, in buffers x (b) and y (D). The first iteration's
  // b is L0 itself; the second iteration starts from 2 c L0 in x (preset by the first) and adds
  // S(D), so it reads D only, not o as well; later ones add S(q - q_i) = 2 c (L0 + avg D_j - D_i).
  // The second sweep adds S(b) into y preset to -2 c (b_i + keep / spread D_i), so that
  // D' = -spread y / (2 c). beta = 1 (spread 0) leaves D = 0: the identity.
  // Afterwards y holds D and the counts, x is zero.
  void hc(int iterations, double alpha, double beta, F4* x, F4* y);

  // Windowed sinc, f = sum_{n=0..N} c_n T_n(A) x with A = (I + avg) / 2 = I - K/2, evaluated by
  // Clenshaw's recurrence b_k = c_k x + 2 A b_{k+1} - b_{k+2} (b_{N+1} = b_{N+2} = 0),
  // f = c_0 x + A b_1 - b_2: N sweeps, no running sum. In displacements: with beta_k the same
  // recurrence for A = 1 (beta_k = c_k + 2 beta_{k+1} - beta_{k+2}) and d_k = b_k - beta_k x,
  //   d_k = (d_{k+1} + avg d_{k+1}) - d_{k+2} + beta_{k+1} L0     (d_N = 0, d_{N-1} = c_N L0)
  //   f = F x + (d_1 + avg d_1) / 2 - d_2 + (beta_1 / 2) L0,      F = sum c_n = f(0),
  // where x is the position relative to the bounding-box centre (F != 1 scales about it, as
  // VTK's normalised coordinates do). Each sweep y <- s (x + avg x) - y + w L0 adds S(x) into y
  // preset to 2 c x_i + (2 c / s) (w L0_i - y_i), then scales it by s / (2 c); the scaling of one
  // sweep and the preset of the next share a vertex pass. Returns F; d receives f - F x, the
  // displacement from o apart from the scaling, scratch is left zero, l0 holds L0 and the counts.
  double sinc(const std::vector<double>& c, F4*& d, F4*& scratch, F4* l0);

 private:
  // acc_i += S(q - q_i) = 2 c_i L(q)_i for q = o + D (q = o where d is null); with `count`, 1 per
  // triangle in acc_i's fourth lane (d must then be null: the lanes of d would add in as well).
  void add_umbrella(const F4* d, F4* acc, bool count) const;
  // acc_i += S(x)_i = 2 c_i avg_j x_j.
  void add_neighbours(const F4* x, F4* acc) const;

  // The triangles' terms added to all their corners.
  void add_umbrella_to(const F4* d, F4* acc, bool count) const;
  void add_neighbours_to(const F4* x, F4* acc) const;
  // acc_i += 2 x_j for each curve edge (i, j) with i a curve vertex.
  void add_curve_neighbours(const F4* x, F4* acc) const;
  // add_neighbours, then update(i) for every vertex i, fused into the scatter: each vertex updated
  // as soon as its sum is complete (scatter_then_finish, while the chunk's vertices are in cache);
  // with a topology the pinned vertices after it, once their sums are put right.
  // The fused pass prefetches x, acc and `ahead` (the other buffer update reads) 64 vertices on:
  // on this machine's VM the hardware prefetch left the stream of L0 missing (docs/PERFORMANCE.md).
  template <class Update>
  void add_neighbours_then(const F4* x, F4* acc, const F4* ahead, Update&& update) const;
  // With a topology: the pinned vertices' accumulators before a sweep, and put back after it.
  void save_pinned(const F4* acc) const;
  void restore_pinned(F4* acc) const;

  const Triangles& t_;
  const Vec3f* o_;
  size_t n_;
  Ticker& ticker_;
  const SmoothTopology* topology_;  // nullptr: every vertex averages over its triangles
  mutable std::vector<F4> saved_;   // save_pinned's copy
  FinishPlan plan_;                 // when each vertex's sums are complete
};

// A filter run on one mesh: the displacements it leaves and where the triangle counts are.
struct FilterRun {
  std::optional<F4Buffer> own_d, own_scratch, own_l0;
  F4* d = nullptr;        // the displacements (x, y, z) and, without l0, the counts (w)
  F4* scratch = nullptr;  // zero
  double gain = 1;        // the sinc's f(0): positions scale by it about the centre
  const F4* counts() const { return own_l0 ? own_l0->data() : d; }
};

// Runs options.method for `iterations` on the n positions o over `triangles` (and `topology`
// when given): the displacement filters of Smoother in two or three fresh buffers.
FilterRun run_filter(const Triangles& triangles, const Vec3f* o, size_t n,
                     const SmoothOptions& options, int iterations, Progress& progress,
                     const SmoothTopology* topology = nullptr);

}  // namespace segmesh
