#include "segmesh/smoothing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "segmesh/first_touch.hpp"
#include "segmesh/detail/triangle_scatter.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

// Vertices per task: enough work to amortise scheduling, small enough to balance two to a few
// dozen cores. Triangles per block of the volume sums: the blocks, not the threads, fix the order
// in which floating-point partial sums are added. Results never depend on the thread count.
constexpr size_t kVertexGrain = 4096;
constexpr size_t kTriangleBlock = 8192;

template <class F>
void for_each_vertex(size_t n, F&& body) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) body(i);
                    });
}

// f(first, last) over fixed blocks of [0, n), the partial results added in block order.
template <class T, class F>
T block_sum(size_t n, F&& f) {
  const size_t blocks = (n + kTriangleBlock - 1) / kTriangleBlock;
  std::vector<T> partial(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    partial[b] = f(b * kTriangleBlock, std::min(n, (b + 1) * kTriangleBlock));
  });
  T total{};
  for (const T& p : partial) total = total + p;
  return total;
}

inline Vec3d to_d(const Vec3f& v) {
  return {v.x, v.y, v.z};
}

void check_options(const SmoothOptions& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("smooth_mesh: " + what); };
  if (o.iterations < 0) fail("iterations must be >= 0, got " + std::to_string(o.iterations));
  if (!std::isfinite(o.lambda)) fail("lambda must be finite");
  if (!(o.alpha >= 0 && o.alpha <= 1)) fail("alpha must be in [0, 1]");
  if (!(o.beta >= 0 && o.beta <= 1)) fail("beta must be in [0, 1]");
  if (!std::isfinite(o.taubin_lambda) || !std::isfinite(o.taubin_mu))
    fail("taubin_lambda and taubin_mu must be finite");
  if (!(o.pass_band > 0 && o.pass_band <= 2)) fail("pass_band must be in (0, 2]");
}

// Cancellation check before and progress report after each iteration.
class Ticker {
 public:
  Ticker(Progress& progress, int total) : progress_(progress), total_(total) {}
  void begin() const { throw_if_cancelled(progress_); }
  void end() { progress_.update(double(++done_) / double(total_)); }

 private:
  Progress& progress_;
  int total_, done_ = 0;
};

// Four floats: a vertex's x, y, z and a fourth lane (the triangle count c_i where a buffer keeps
// it). GCC's and Clang's vector extension: one SSE instruction per operation on x86-64, plain
// floats elsewhere. The filters' state and sums are small quantities (displacements, differences
// of neighbouring positions), which float holds to ~1e-7 of their size.
typedef float F4 __attribute__((vector_size(16)));

inline F4 load3(const Vec3f& p) {
  return F4{p.x, p.y, p.z, 0.0f};
}
inline F4 with_w(F4 a, float w) {
  return F4{a[0], a[1], a[2], w};
}
inline Vec3d xyz_d(F4 a) {
  return {a[0], a[1], a[2]};
}
// (a.y, a.z, a.x, a.w), for the cross product in three shuffles.
inline F4 yzx(F4 a) {
  return __builtin_shufflevector(a, a, 1, 2, 0, 3);
}
inline F4 cross3(F4 a, F4 b) {
  return yzx(a * yzx(b) - yzx(a) * b);
}
// 1 / (2 c) for a vertex with c triangles: a sum over its triangles' other two corners counts
// each neighbour twice on a closed mesh. 0 for a vertex without triangles.
inline float half_inverse(float c) {
  return c > 0 ? 0.5f / c : 0.0f;
}

// n F4, zero. From calloc, which takes large blocks as fresh pages from the kernel, already zero
// (and clears smaller ones); their pages are made resident by every thread first (first_touch.hpp,
// which leaves zero pages zero). glibc's malloc aligns to 16 bytes on 64-bit systems, as F4 needs.
class F4Buffer {
 public:
  explicit F4Buffer(size_t n)
      : p_(static_cast<F4*>(std::calloc(std::max<size_t>(n, 1), sizeof(F4)))) {
    if (!p_) throw std::bad_alloc();
    if (reinterpret_cast<uintptr_t>(p_.get()) % alignof(F4) != 0)
      throw std::logic_error("smoothing: calloc returned memory aligned below 16 bytes");
    first_touch(p_.get(), n * sizeof(F4));
  }
  F4* data() const { return p_.get(); }

 private:
  struct Free {
    void operator()(F4* p) const { std::free(p); }
  };
  std::unique_ptr<F4, Free> p_;
};

// The triangles of a mesh as the sweeps visit them (triangle_scatter.hpp). Triangles with a
// repeated corner add nothing to the umbrella sums (they have no area and their edges are the
// other triangles').
struct Triangles {
  const uint32_t* idx;
  TriangleChunks chunks;

  template <class F>
  void each(F&& f) const {
    scatter_triangles(chunks, [&](size_t t0, size_t t1) {
      for_each_interleaved(t0, t1,
                           [&](size_t t) { f(idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]); });
    });
  }
  template <class F>
  void each_proper(F&& f) const {
    each([&](uint32_t a, uint32_t b, uint32_t c) {
      if (a != b && b != c && c != a) f(a, b, c);
    });
  }
};

// acc_i += (b - a) x (c - a) for each corner i of every triangle (a, b, c): twice the area
// vector of the triangles at i, for positions pos(j) (F4).
template <class Pos>
void add_area_vectors(const Triangles& t, Pos&& pos, F4* acc) {
  t.each([&](uint32_t a, uint32_t b, uint32_t c) {
    const F4 pa = pos(a);
    const F4 n = cross3(pos(b) - pa, pos(c) - pa);
    acc[a] += n;
    acc[b] += n;
    acc[c] += n;
  });
}

// The unit vector of acc_i's x, y, z, or `otherwise` where that is zero (or not finite).
inline F4 unit_or(F4 v, F4 otherwise) {
  const float length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return length > 0 && std::isfinite(length) ? with_w(v * (1.0f / length), 0.0f) : otherwise;
}

// mesh.normals from the area vectors of mesh.positions (scratch: zero, nv entries).
void write_normals(TriMesh& mesh, const Triangles& t, F4* scratch) {
  const Vec3f* p = mesh.positions.data();
  add_area_vectors(
      t, [&](uint32_t i) { return load3(p[i]); }, scratch);
  resize_zeroed(mesh.normals, mesh.positions.size());
  for_each_vertex(mesh.positions.size(), [&](size_t i) {
    const F4 n = unit_or(scratch[i], F4{0, 0, 1, 0});
    mesh.normals[i] = {n[0], n[1], n[2]};
  });
}

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
class Smoother {
 public:
  Smoother(const Triangles& triangles, const Vec3f* original, size_t n, Ticker& ticker)
      : t_(triangles), o_(original), n_(n), ticker_(ticker) {}

  // acc_i += S(q - q_i) = 2 c_i L(q)_i for q = o + D (q = o where d is null); with `count`, 1 per
  // triangle in acc_i's fourth lane (d must then be null: the lanes of d would add in as well).
  void add_umbrella(const F4* d, F4* acc, bool count) const {
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
  // acc_i += S(x)_i = 2 c_i avg_j x_j.
  void add_neighbours(const F4* x, F4* acc) const {
    t_.each_proper([&](uint32_t a, uint32_t b, uint32_t c) {
      const F4 xa = x[a], xb = x[b], xc = x[c];
      acc[a] += xb + xc;
      acc[b] += xa + xc;
      acc[c] += xa + xb;
    });
  }

  // Laplacian steps p' = p + f L(p), one per factor: D' = D + f L(o + D). `per_tick` factors
  // make one iteration. d holds D and the counts, scratch is zero; afterwards the same.
  void laplacian(const std::vector<double>& factors, size_t per_tick, F4*& d, F4*& scratch) {
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
  void hc(int iterations, double alpha, double beta, F4* x, F4* y) {
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
  double sinc(const std::vector<double>& c, F4*& d, F4*& scratch, F4* l0) {
    const int n = static_cast<int>(c.size()) - 1;
    std::vector<double> beta(n + 3, 0.0);
    for (int k = n; k >= 1; --k) beta[k] = c[k] + 2 * beta[k + 1] - beta[k + 2];
    double gain = 0;
    for (double x : c) gain += x;
    // The sweeps, last first: sweep k (k = n - 2 .. 1, then the final one) with weight w, scale s.
    struct Sweep {
      float w, s;
    };
    std::vector<Sweep> sweeps;
    for (int k = n - 2; k >= 1; --k) sweeps.push_back({static_cast<float>(beta[k + 1]), 1.0f});
    sweeps.push_back({static_cast<float>(0.5 * beta[1]), 0.5f});
    auto preset = [&](size_t i, float cnt, F4 x, F4 y, const Sweep& sw) {
      return (2 * cnt) * x + (2 * cnt / sw.s) * (sw.w * l0[i] - y);
    };
    // cur = d_{k+1}, prev = d_{k+2}, starting at k = N - 2: d_{N-1} = c_N L0, d_N = 0.
    F4* cur = d;
    F4* prev = scratch;
    const float c_n = n >= 2 ? static_cast<float>(c[n]) : 0.0f;
    ticker_.begin();
    add_umbrella(nullptr, l0, true);
    for_each_vertex(n_, [&](size_t i) {
      const float cnt = l0[i][3];
      const F4 l = half_inverse(cnt) * l0[i];
      l0[i] = with_w(l, cnt);
      cur[i] = c_n * l;
      prev[i] = preset(i, cnt, cur[i], F4{}, sweeps[0]);
    });
    ticker_.end();
    for (size_t k = 0; k < sweeps.size(); ++k) {
      const bool last = k + 1 == sweeps.size();
      if (!last || n >= 2) ticker_.begin();
      add_neighbours(cur, prev);
      for_each_vertex(n_, [&](size_t i) {
        const float cnt = l0[i][3];
        const F4 y = (sweeps[k].s * half_inverse(cnt)) * prev[i];
        prev[i] = y;
        cur[i] = last ? F4{} : preset(i, cnt, y, cur[i], sweeps[k + 1]);
      });
      std::swap(cur, prev);
      if (!last || n >= 2) ticker_.end();
    }
    d = cur;  // the result
    scratch = prev;
    return gain;
  }

 private:
  const Triangles& t_;
  const Vec3f* o_;
  size_t n_;
  Ticker& ticker_;
};

// Coefficients of 6 V(delta) = k0 + k1 delta + k2 delta^2 + k3 delta^3, the volume after every
// vertex moves by delta along its unit normal, and 6 times the original volume.
struct VolumeCubic {
  double k0 = 0, k1 = 0, k2 = 0, k3 = 0, original = 0;
  VolumeCubic operator+(const VolumeCubic& o) const {
    return {k0 + o.k0, k1 + o.k1, k2 + o.k2, k3 + o.k3, original + o.original};
  }
};

struct Restoration {
  bool keep_original = false;
  double delta = 0;  // offset along the unit normals
};

// Gives the smoothed positions s(i) the enclosed volume V0 of the original ones o(i) (both
// relative to one centre, for well-conditioned sums): every vertex moves along its area-weighted
// unit normal (into `normal`) by the one offset delta that restores it. The volume after the move
// is a cubic in delta (VolumeCubic), solved by Newton's method from delta = 0 (whose first step
// is the first-order one, (V0 - V) / (dV/ddelta)). A part that smoothing nearly erased (below a
// quarter of its volume: specks of a few voxels) keeps its original positions instead; a mesh
// that encloses no positive volume is left as smoothed.
// `smoothed` holds the smoothed positions relative to the centre (x, y, z); `normal` is zero.
template <class Original>
Restoration restore_volume(const Triangles& t, const std::vector<uint32_t>& idx,
                           Original&& original, const F4* smoothed, size_t nv, F4* normal) {
  const size_t nt = idx.size() / 3;
  // One pass for the normals, one over the triangles for both volumes and the cubic (the
  // normals are wasted only in the rare cases that return early).
  add_area_vectors(
      t, [&](uint32_t i) { return smoothed[i]; }, normal);
  for_each_vertex(nv, [&](size_t i) { normal[i] = unit_or(normal[i], F4{}); });
  const VolumeCubic k = block_sum<VolumeCubic>(nt, [&](size_t t0, size_t t1) {
    VolumeCubic s;
    for (size_t t = t0; t < t1; ++t) {
      const uint32_t* x = &idx[3 * t];
      s.original += dot(original(x[0]), cross(original(x[1]), original(x[2])));
      const Vec3d a = xyz_d(smoothed[x[0]]), b = xyz_d(smoothed[x[1]]), c = xyz_d(smoothed[x[2]]);
      const Vec3d na = xyz_d(normal[x[0]]), nb = xyz_d(normal[x[1]]), nc = xyz_d(normal[x[2]]);
      const Vec3d bc = cross(b, c), nbc = cross(nb, c), bnc = cross(b, nc), nbnc = cross(nb, nc);
      s.k0 += dot(a, bc);
      s.k1 += dot(na, bc) + dot(a, nbc) + dot(a, bnc);
      s.k2 += dot(na, nbc) + dot(na, bnc) + dot(a, nbnc);
      s.k3 += dot(na, nbnc);
    }
    return s;
  });
  const double target = k.original, volume = k.k0;  // both times 6
  if (!(target > 0)) return {};  // not a closed outward-wound surface: nothing to restore
  if (volume < 0.25 * target) return {.keep_original = true};
  if (std::abs(volume - target) <= 1e-9 * target) return {};
  double delta = 0;  // no step if the derivative k1 is not positive
  for (int step = 0; step < 50; ++step) {
    const double g = k.k0 + delta * (k.k1 + delta * (k.k2 + delta * k.k3)) - target;
    const double dg = k.k1 + delta * (2 * k.k2 + delta * 3 * k.k3);
    if (!(dg > 0)) break;
    const double change = g / dg;
    if (!std::isfinite(change)) break;
    delta -= change;
    if (std::abs(change) <= 1e-15 * std::abs(delta)) break;
  }
  return {.delta = std::isfinite(delta) ? delta : 0.0};
}

// The centre of the bounding box of the positions (exact: minima and maxima do not depend on the
// order of evaluation). Each block reads its positions as a flat run of floats, twelve lanes at a
// time (four positions: lane k holds coordinate k mod 3), with comparisons and selects that
// compilers vectorise (std::min on floats they do not): a third of the time of a loop over Vec3f.
Vec3d box_centre(const std::vector<Vec3f>& p) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  struct Box {
    Vec3f lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    Box operator+(const Box& o) const {
      return {{std::min(lo.x, o.lo.x), std::min(lo.y, o.lo.y), std::min(lo.z, o.lo.z)},
              {std::max(hi.x, o.hi.x), std::max(hi.y, o.hi.y), std::max(hi.z, o.hi.z)}};
    }
  };
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  const Box box = block_sum<Box>(p.size(), [&](size_t i0, size_t i1) {
    constexpr size_t kLanes = 12;
    float lo[kLanes], hi[kLanes];
    std::fill(lo, lo + kLanes, kInf);
    std::fill(hi, hi + kLanes, -kInf);
    const float* f = &p[i0].x;
    const size_t n = 3 * (i1 - i0);
    size_t k = 0;
    for (; k + kLanes <= n; k += kLanes) {
      for (size_t l = 0; l < kLanes; ++l) {
        const float v = f[k + l];
        lo[l] = v < lo[l] ? v : lo[l];
        hi[l] = v > hi[l] ? v : hi[l];
      }
    }
    for (size_t l = 0; k + l < n; ++l) {  // the last positions, fewer than four
      lo[l] = std::min(lo[l], f[k + l]);
      hi[l] = std::max(hi[l], f[k + l]);
    }
    Box b;
    for (size_t l = 0; l < kLanes; l += 3)
      b = b + Box{{lo[l], lo[l + 1], lo[l + 2]}, {hi[l], hi[l + 1], hi[l + 2]}};
    return b;
  });
  return 0.5 * (to_d(box.lo) + to_d(box.hi));
}

void smooth_with(TriMesh& mesh, const SmoothOptions& options, int iterations, Progress& progress) {
  const size_t nv = mesh.positions.size();
  const std::vector<uint32_t>& idx = mesh.indices;
  const Triangles triangles{idx.data(), triangle_chunks(idx)};
  const Vec3f* o = mesh.positions.data();
  // The centre of the volume sums and of the sinc filter's scaling (not needed otherwise).
  const bool centred = options.method == SmoothMethod::sinc || options.preserve_volume;
  const Vec3d centre = centred ? box_centre(mesh.positions) : Vec3d{};

  Ticker ticker(progress, iterations);
  Smoother smoother(triangles, o, nv, ticker);
  // Two buffers of four floats per vertex (three for the sinc), zero: every filter leaves its
  // displacements in d and scratch zero again.
  F4Buffer own_d(nv), own_scratch(nv);
  std::optional<F4Buffer> own_l0;
  F4* d = own_d.data();
  F4* scratch = own_scratch.data();
  double gain = 1;
  switch (options.method) {
    case SmoothMethod::laplacian:
      smoother.laplacian(std::vector<double>(iterations, options.lambda), 1, d, scratch);
      break;
    case SmoothMethod::taubin: {
      std::vector<double> factors;
      for (int it = 0; it < iterations; ++it) {
        factors.push_back(options.taubin_lambda);
        factors.push_back(options.taubin_mu);
      }
      smoother.laplacian(factors, 2, d, scratch);
      break;
    }
    case SmoothMethod::hc:
      smoother.hc(iterations, options.alpha, options.beta, scratch, d);
      break;
    case SmoothMethod::sinc:
      own_l0.emplace(nv);
      gain = smoother.sinc(
          windowed_sinc_coefficients(iterations, options.pass_band, options.sinc_unit_gain), d,
          scratch, own_l0->data());
      break;
    case SmoothMethod::none:
      break;
  }
  // The triangle counts ride in the fourth lane of the sinc's L0, of the displacements otherwise.
  const F4* counts = own_l0 ? own_l0->data() : d;
  // Vertices in no triangle with three distinct corners keep their positions.
  auto has_triangles = [&](size_t i) { return counts[i][3] > 0; };
  if (!options.preserve_volume) {
    for_each_vertex(nv, [&](size_t i) {
      if (has_triangles(i))
        mesh.positions[i] = to_float(centre + gain * (to_d(o[i]) - centre) + xyz_d(d[i]));
    });
  } else {
    // Position i relative to the centre: before (original) and after smoothing. The smoothed
    // ones replace the displacements in d (x, y, z), rounded to float once, because the volume
    // restoration reads each many times; the count goes to the fourth lane. The rounding is at
    // most half a float step of the box's half-diagonal (4e-6 mm for a 200 mm box): no more than
    // the final rounding of the world positions for a mesh away from the world origin, and a few
    // nanometres in any case.
    for_each_vertex(nv, [&](size_t i) {
      const Vec3d p = gain * (to_d(o[i]) - centre) + xyz_d(d[i]);
      d[i] = F4{static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z),
                counts[i][3]};
    });
    own_l0.reset();
    const auto original = [&](size_t i) { return to_d(o[i]) - centre; };
    const Restoration r = restore_volume(triangles, idx, original, d, nv, scratch);
    // The positions, and scratch (the normals) zero again for write_normals.
    const bool moved = r.delta != 0;
    for_each_vertex(nv, [&](size_t i) {
      if (!r.keep_original && d[i][3] > 0) {
        Vec3d p = centre + xyz_d(d[i]);
        if (moved) p = p + r.delta * xyz_d(scratch[i]);
        mesh.positions[i] = to_float(p);
      }
      scratch[i] = F4{};
    });
  }
  write_normals(mesh, triangles, scratch);
}

}  // namespace

std::string_view smooth_method_name(SmoothMethod method) {
  switch (method) {
    case SmoothMethod::none:
      return "none";
    case SmoothMethod::laplacian:
      return "laplacian";
    case SmoothMethod::hc:
      return "hc";
    case SmoothMethod::taubin:
      return "taubin";
    case SmoothMethod::sinc:
      return "sinc";
  }
  return "?";
}

std::optional<SmoothMethod> parse_smooth_method(std::string_view name) {
  for (SmoothMethod m : {SmoothMethod::none, SmoothMethod::laplacian, SmoothMethod::hc,
                         SmoothMethod::taubin, SmoothMethod::sinc})
    if (name == smooth_method_name(m)) return m;
  return std::nullopt;
}

int default_smooth_iterations(SmoothMethod method) {
  switch (method) {
    case SmoothMethod::none:
      return 0;
    case SmoothMethod::laplacian:
      return 2;
    case SmoothMethod::hc:
      return 2;
    case SmoothMethod::taubin:
      return 20;
    case SmoothMethod::sinc:
      return 20;
  }
  return 0;
}

std::vector<double> windowed_sinc_coefficients(int iterations, double pass_band, bool unit_gain) {
  if (iterations < 1) throw std::invalid_argument("windowed_sinc_coefficients: iterations < 1");
  if (!(pass_band > 0 && pass_band <= 2))
    throw std::invalid_argument("windowed_sinc_coefficients: pass_band outside (0, 2]");
  const int n = iterations;
  const double pi = std::numbers::pi;
  const double theta_pb = std::acos(1 - 0.5 * pass_band);  // the cut-off as an angle, [0, pi/2]
  std::vector<double> window(n + 1), c(n + 1), dc(n + 1);
  for (int i = 0; i <= n; ++i) window[i] = 0.54 + 0.46 * std::cos(i * pi / (n + 1));
  // Chebyshev basis at the pass band: T_i(1 - k_pb/2) = cos(i theta_pb).
  std::vector<double> t_pb(n + 1);
  for (int i = 0; i <= n; ++i) t_pb[i] = std::cos(i * theta_pb);

  // The cut-off is moved by sigma until the windowed series passes k_pb with gain 1. The Newton
  // step uses the derivative of the series in its argument (VTK's choice, kept so that the
  // coefficients and so the smoothed meshes match VTK's and Slicer's).
  double sigma = 0;
  for (int step = 0; step < 500; ++step) {
    const double cut = theta_pb + sigma;
    c[0] = window[0] * cut / pi;
    for (int i = 1; i <= n; ++i) c[i] = 2 * window[i] * std::sin(i * cut) / (i * pi);
    if (n == 1) break;  // a first-order series has no freedom left: it shrinks
    dc[n] = dc[n - 1] = 0;
    for (int i = n - 2; i >= 0; --i) dc[i] = dc[i + 2] + 2.0 * (i + 1) * c[i + 1];
    double f = 0, df = 0;
    for (int i = 0; i <= n; ++i) {
      f += c[i] * t_pb[i];
      df += dc[i] * t_pb[i];
    }
    if (std::abs(f - 1) < 1e-3) break;
    sigma -= (f - 1) / df;
  }
  if (unit_gain) {
    double sum = 0;
    for (double x : c) sum += x;
    for (double& x : c) x /= sum;
  }
  return c;
}

void compute_vertex_normals(TriMesh& mesh) {
  const Triangles triangles{mesh.indices.data(), triangle_chunks(mesh.indices)};
  F4Buffer scratch(mesh.positions.size());
  write_normals(mesh, triangles, scratch.data());
}

void smooth_mesh(TriMesh& mesh, const SmoothOptions& options, Progress& progress) {
  check_options(options);
  if (options.method == SmoothMethod::none) return;
  if (mesh.positions.empty()) {
    mesh.normals.clear();
    return;
  }
  const int iterations =
      options.iterations > 0 ? options.iterations : default_smooth_iterations(options.method);
  smooth_with(mesh, options, iterations, progress);
}

}  // namespace segmesh
