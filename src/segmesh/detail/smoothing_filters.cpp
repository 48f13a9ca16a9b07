#include "segmesh/detail/smoothing_filters.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <utility>

namespace segmesh {

void Smoother::add_umbrella_to(const F4* d, F4* acc, bool count) const {
  const F4 one = count ? F4{0, 0, 0, 1} : F4{};
  t_.each_proper([&](uint32_t a, uint32_t b, uint32_t c) {
    const F4 oa = load3(o_[a]);
    F4 ab = load3(o_[b]) - oa, ac = load3(o_[c]) - oa;
    if (d) {
      ab += d[b] - d[a];
      ac += d[c] - d[a];
    }
    const F4 bc = ac - ab;
    acc[a] += ab + ac + one;
    acc[b] += bc - ab + one;
    acc[c] += one - ac - bc;
  });
}

namespace {

// acc_i += x_j + x_k for each corner i of triangle (i, j, k).
auto neighbour_terms(const F4* x, F4* acc) {
  return [=](uint32_t a, uint32_t b, uint32_t c) {
    const F4 xa = x[a], xb = x[b], xc = x[c];
    acc[a] += xb + xc;
    acc[b] += xa + xc;
    acc[c] += xa + xb;
  };
}

}  // namespace

void Smoother::add_neighbours_to(const F4* x, F4* acc) const {
  t_.each_proper(neighbour_terms(x, acc));
}

template <class Update>
void Smoother::add_neighbours_then(const F4* x, F4* acc, const F4* ahead, Update&& update) const {
  constexpr size_t kAhead = 64;
  // With a topology the pinned (curve and fixed) vertices wait: their sums are put right after the
  // scatter (saved preset, plus the curve edges' terms, which read pinned neighbours' x only, so
  // those must not have been updated yet), then they are updated. Sheet vertices are updated in
  // the scatter as without one: the same sums, the same results.
  const SmoothRole* role = topology_ ? topology_->role.data() : nullptr;
  if (role) save_pinned(acc);
  t_.each_proper_then(plan_, neighbour_terms(x, acc), [&](size_t v0, size_t v1) {
    for (size_t i = v0; i != v1; ++i) {
      __builtin_prefetch(ahead + i + kAhead);
      __builtin_prefetch(x + i + kAhead);
      __builtin_prefetch(acc + i + kAhead);
      if (!role || role[i] == SmoothRole::kSheet) update(i);
    }
  });
  if (!role) return;
  restore_pinned(acc);
  add_curve_neighbours(x, acc);
  const std::vector<uint32_t>& pinned = topology_->pinned;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pinned.size(), kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t k = r.begin(); k != r.end(); ++k) update(pinned[k]);
                    });
}

void Smoother::add_curve_neighbours(const F4* x, F4* acc) const {
  const SmoothRole* role = topology_->role.data();
  for (const auto& [a, b] : topology_->curve_edges) {
    if (role[a] == SmoothRole::kCurve) acc[a] += x[b] + x[b];
    if (role[b] == SmoothRole::kCurve) acc[b] += x[a] + x[a];
  }
}

void Smoother::save_pinned(const F4* acc) const {
  const std::vector<uint32_t>& pinned = topology_->pinned;
  saved_.resize(pinned.size());
  for (size_t i = 0; i < pinned.size(); ++i) saved_[i] = acc[pinned[i]];
}

void Smoother::restore_pinned(F4* acc) const {
  const std::vector<uint32_t>& pinned = topology_->pinned;
  for (size_t i = 0; i < pinned.size(); ++i) acc[pinned[i]] = saved_[i];
}

void Smoother::add_umbrella(const F4* d, F4* acc, bool count) const {
  if (!topology_) {
    add_umbrella_to(d, acc, count);
    return;
  }
  const SmoothRole* role = topology_->role.data();
  save_pinned(acc);
  add_umbrella_to(d, acc, count);
  restore_pinned(acc);
  // A curve edge as one triangle at each curve end: its neighbour twice, one count.
  const F4 one = count ? F4{0, 0, 0, 1} : F4{};
  for (const auto& [a, b] : topology_->curve_edges) {
    F4 ab = load3(o_[b]) - load3(o_[a]);
    if (d) ab += d[b] - d[a];
    if (role[a] == SmoothRole::kCurve) acc[a] += ab + ab + one;
    if (role[b] == SmoothRole::kCurve) acc[b] += one - ab - ab;
  }
}

void Smoother::add_neighbours(const F4* x, F4* acc) const {
  if (!topology_) {
    add_neighbours_to(x, acc);
    return;
  }
  save_pinned(acc);
  add_neighbours_to(x, acc);
  restore_pinned(acc);
  add_curve_neighbours(x, acc);
}

void Smoother::laplacian(const std::vector<double>& factors, size_t per_tick, F4*& d,
                         F4*& scratch) {
  for (size_t s = 0; s < factors.size(); ++s) {
    if (s % per_tick == 0) ticker_.begin();
    const float f = static_cast<float>(factors[s]);
    const bool first = s == 0;
    add_umbrella(first ? nullptr : d, scratch, first);
    for_each_vertex(n_, [&](size_t i) {
      const float c = first ? scratch[i][3] : d[i][3];
      const F4 old = first ? F4{} : d[i];
      scratch[i] = with_w(old + (f * half_inverse(c)) * scratch[i], c);
      d[i] = F4{};
    });
    std::swap(d, scratch);
    if (s % per_tick == per_tick - 1) ticker_.end();
  }
}

void Smoother::hc(int iterations, double alpha, double beta, F4* x, F4* y) {
  const float keep = static_cast<float>(1 - alpha), spread = static_cast<float>(1 - beta);
  for (int it = 0; it < iterations; ++it) {
    ticker_.begin();
    if (spread == 0) {  // D stays 0; y needs the counts
      if (it == 0) {
        add_umbrella(nullptr, x, true);
        for_each_vertex(n_, [&](size_t i) {
          y[i] = F4{0, 0, 0, x[i][3]};
          x[i] = F4{};
        });
      }
      ticker_.end();
      continue;
    }
    const bool first = it == 0, second = it == 1;
    if (first) {
      add_umbrella(nullptr, x, true);
    } else if (second) {
      add_neighbours(y, x);
    } else {
      add_umbrella(y, x, false);
    }
    const float ratio = keep / spread;
    for_each_vertex(n_, [&](size_t i) {
      const float c = first ? x[i][3] : y[i][3];
      const F4 di = first ? F4{} : y[i];
      F4 b = half_inverse(c) * x[i];
      if (!first) b += (second ? -keep : 1 - keep) * di;
      x[i] = with_w(b, c);
      y[i] = (-2 * c) * (b + ratio * di);
    });
    add_neighbours(x, y);
    const bool next_second = it == 0 && iterations > 1;
    for_each_vertex(n_, [&](size_t i) {
      const float c = x[i][3];
      y[i] = with_w((-spread * half_inverse(c)) * y[i], c);
      x[i] = next_second ? with_w((2 * c) * x[i], 0.0f) : F4{};
    });
    ticker_.end();
  }
}

double Smoother::sinc(const std::vector<double>& c, F4*& d, F4*& scratch, F4* l0) {
  const int n = static_cast<int>(c.size()) - 1;
  std::vector<double> beta(n + 3, 0.0);
  for (int k = n; k >= 1; --k) beta[k] = c[k] + 2 * beta[k + 1] - beta[k + 2];
  double gain = 0;
  for (double x : c) gain += x;
  // The sweeps, last first: sweep k (k = n - 2 .. 1, then the final one) with weight w, scale s.
  // s is 1 or 1/2, so multiplying by inv_s = 1 / s is exact: the same numbers as dividing by s,
  // without a division per vertex.
  struct Sweep {
    float w, s, inv_s;
  };
  std::vector<Sweep> sweeps;
  for (int k = n - 2; k >= 1; --k) sweeps.push_back({static_cast<float>(beta[k + 1]), 1.0f, 1.0f});
  sweeps.push_back({static_cast<float>(0.5 * beta[1]), 0.5f, 2.0f});
  // The accumulator of sweep `sw` at vertex i (count cnt, L0 l): 2 c x + (2 c / s) (w L0 - y).
  auto preset = [](float cnt, F4 l, F4 x, F4 y, const Sweep& sw) {
    return (2 * cnt) * x + ((2 * cnt) * sw.inv_s) * (sw.w * l - y);
  };
  // cur = d_{k+1}, prev = d_{k+2}, starting at k = N - 2: d_{N-1} = c_N L0, d_N = 0.
  F4* cur = d;
  F4* prev = scratch;
  const float c_n = n >= 2 ? static_cast<float>(c[n]) : 0.0f;
  ticker_.begin();
  add_umbrella(nullptr, l0, true);
  {
    const Sweep first = sweeps[0];
    F4* const x = cur;
    F4* const y = prev;
    for_each_vertex(n_, [=](size_t i) {
      const float cnt = l0[i][3];
      const F4 scaled = half_inverse(cnt) * l0[i];
      const F4 l = with_w(scaled, cnt);
      l0[i] = l;
      const F4 xi = c_n * scaled;
      x[i] = xi;
      y[i] = preset(cnt, l, xi, F4{}, first);
    });
  }
  ticker_.end();
  for (size_t k = 0; k < sweeps.size(); ++k) {
    const bool last = k + 1 == sweeps.size();
    if (!last || n >= 2) ticker_.begin();
    // The sweep and its vertex pass (on locals: the pointers and constants copied into the task,
    // so that the stores to the buffers, floats, do not make the compiler reload them).
    const float s = sweeps[k].s;
    F4* const x = cur;
    F4* const acc = prev;
    if (last) {
      add_neighbours_then(x, acc, l0, [=](size_t i) {
        acc[i] = (s * half_inverse(l0[i][3])) * acc[i];
        x[i] = F4{};
      });
    } else {
      const Sweep next = sweeps[k + 1];
      add_neighbours_then(x, acc, l0, [=](size_t i) {
        const F4 l = l0[i];
        const float cnt = l[3];
        const F4 y = (s * half_inverse(cnt)) * acc[i];
        acc[i] = y;
        x[i] = preset(cnt, l, y, x[i], next);
      });
    }
    std::swap(cur, prev);
    if (!last || n >= 2) ticker_.end();
  }
  d = cur;  // the result
  scratch = prev;
  return gain;
}

FilterRun run_filter(const Triangles& triangles, const Vec3f* o, size_t nv,
                     const SmoothOptions& options, int iterations, Progress& progress,
                     const SmoothTopology* topology) {
  Ticker ticker(progress, iterations);
  Smoother smoother(triangles, o, nv, ticker, topology);
  // Two buffers of four floats per vertex (three for the sinc), zero: every filter leaves its
  // displacements in d and scratch zero again.
  FilterRun run;
  run.d = run.own_d.emplace(nv).data();
  run.scratch = run.own_scratch.emplace(nv).data();
  switch (options.method) {
    case SmoothMethod::laplacian:
      smoother.laplacian(std::vector<double>(iterations, options.lambda), 1, run.d, run.scratch);
      break;
    case SmoothMethod::taubin: {
      std::vector<double> factors;
      for (int it = 0; it < iterations; ++it) {
        factors.push_back(options.taubin_lambda);
        factors.push_back(options.taubin_mu);
      }
      smoother.laplacian(factors, 2, run.d, run.scratch);
      break;
    }
    case SmoothMethod::hc:
      smoother.hc(iterations, options.alpha, options.beta, run.scratch, run.d);
      break;
    case SmoothMethod::sinc:
      run.own_l0.emplace(nv);
      run.gain = smoother.sinc(
          windowed_sinc_coefficients(iterations, options.pass_band, options.sinc_unit_gain), run.d,
          run.scratch, run.own_l0->data());
      break;
    case SmoothMethod::none:
      break;
  }
  return run;
}

}  // namespace segmesh
