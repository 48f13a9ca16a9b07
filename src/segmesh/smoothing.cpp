#include "segmesh/smoothing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "segmesh/first_touch.hpp"
#include "segmesh/mesh_adjacency.hpp"
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

inline Vec3d to_d(const Vec3f& v) { return {v.x, v.y, v.z}; }
inline Vec3d to_d(const Vec3d& v) { return v; }
template <class T>
T from_d(const Vec3d& v);
template <>
inline Vec3f from_d<Vec3f>(const Vec3d& v) { return to_float(v); }
template <>
inline Vec3d from_d<Vec3d>(const Vec3d& v) { return v; }

// The mean of x over a non-empty row, summed in double.
template <class Index, class V>
inline Vec3d row_mean(const Index* first, const Index* last, const V* x) {
  double sx = 0, sy = 0, sz = 0;
  for (const Index* j = first; j != last; ++j) {
    const V& p = x[*j];
    sx += p.x;
    sy += p.y;
    sz += p.z;
  }
  const double inv = 1.0 / double(last - first);
  return {sx * inv, sy * inv, sz * inv};
}

// The vertex graph and the triangles at each vertex. Closed oriented manifold meshes (Marching
// Cubes, Dual Contouring) keep one array: each vertex's neighbours in fan order, consecutive
// neighbours spanning its triangles. Other meshes keep the corner rows for the triangles and
// separate rows of neighbours (the other corners of the vertex's triangles, each once, sorted,
// the vertex itself excluded).
template <class Index>
struct Adjacency {
  VertexRows<Index> rows;  // rings, or corner rows
  bool fans = false;
  VertexRows<Index> neighbours;  // meshes that are not closed fans only

  const VertexRows<Index>& graph() const { return fans ? rows : neighbours; }

  // Twice the area vector of the triangles at vertex i: sum of (b - p_i) x (c - p_i) over its
  // triangles (i, b, c), for positions pos(j) (double).
  template <class Pos>
  Vec3d area_normal(const std::vector<uint32_t>& idx, size_t i, Pos&& pos) const {
    Vec3d sum{};
    const size_t d = rows.size(i);
    if (d == 0) return sum;
    const Vec3d p = pos(i);
    const Index* r = rows.begin(i);
    if (fans) {
      const Vec3d first = pos(r[0]) - p;
      Vec3d prev = first;
      for (size_t k = 1; k < d; ++k) {
        const Vec3d cur = pos(r[k]) - p;
        sum = sum + cross(prev, cur);
        prev = cur;
      }
      return sum + cross(prev, first);
    }
    for (size_t k = 0; k < d; ++k)
      sum = sum + cross(pos(corner_next(idx, r[k])) - p, pos(corner_prev(idx, r[k])) - p);
    return sum;
  }
};

// Rows of unique neighbours from corner rows: two parallel passes (count, fill), each gathering a
// vertex's corners into a per-task buffer; deterministic because each row is a sorted set.
template <class Index>
VertexRows<Index> unique_neighbours(const std::vector<uint32_t>& idx, const VertexRows<Index>& corners) {
  const size_t nv = corners.offsets.size() - 1;
  auto gather = [&](size_t i, std::vector<uint32_t>& buffer) {
    buffer.clear();
    for (const Index* c = corners.begin(i); c != corners.end(i); ++c) {
      for (const uint32_t v : {corner_next(idx, *c), corner_prev(idx, *c)})
        if (v != i) buffer.push_back(v);
    }
    std::sort(buffer.begin(), buffer.end());
    buffer.erase(std::unique(buffer.begin(), buffer.end()), buffer.end());
  };
  VertexRows<Index> rows;
  rows.offsets.assign(nv + 1, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::vector<uint32_t> buffer;
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        gather(i, buffer);
                        rows.offsets[i + 1] = static_cast<Index>(buffer.size());
                      }
                    });
  for (size_t i = 0; i < nv; ++i) rows.offsets[i + 1] += rows.offsets[i];
  rows.entries.resize(rows.offsets[nv]);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::vector<uint32_t> buffer;
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        gather(i, buffer);
                        std::copy(buffer.begin(), buffer.end(),
                                  rows.entries.begin() + static_cast<ptrdiff_t>(rows.offsets[i]));
                      }
                    });
  return rows;
}

template <class Index>
Adjacency<Index> build_adjacency(const std::vector<uint32_t>& idx, size_t nv, bool with_neighbours) {
  Adjacency<Index> a;
  a.rows = vertex_corners<Index>(idx, nv);
  a.fans = corners_to_rings(idx, a.rows);
  if (a.fans) return a;
  a.rows = vertex_corners<Index>(idx, nv);  // the failed conversion left them half rewritten
  if (with_neighbours) a.neighbours = unique_neighbours(idx, a.rows);
  return a;
}

// Unit normals from the area-weighted sum at each vertex; (0, 0, 1) where that sum vanishes.
template <class Index>
void write_normals(TriMesh& mesh, const Adjacency<Index>& adj) {
  const Vec3f* pos = mesh.positions.data();
  resize_zeroed(mesh.normals, mesh.positions.size());
  for_each_vertex(mesh.positions.size(), [&](size_t i) {
    const Vec3d sum = adj.area_normal(mesh.indices, i, [&](size_t j) { return to_d(pos[j]); });
    const double length = norm(sum);
    mesh.normals[i] =
        length > 0 && std::isfinite(length) ? to_float((1.0 / length) * sum) : Vec3f{0, 0, 1};
  });
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

// Float triples: the filters' state and sums are small quantities (displacements, differences
// of neighbouring positions), which float holds to ~1e-7 of their size.
inline Vec3f add(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3f sub(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3f mul(float s, Vec3f a) { return {s * a.x, s * a.y, s * a.z}; }
inline Vec3f fcross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// n float triples, allocated without initialisation (every pass writes what a later one reads;
// Vec3f is an implicit-lifetime aggregate, so the storage holds its objects from the start).
class Vec3fBuffer {
 public:
  explicit Vec3fBuffer(size_t n) : p_(static_cast<Vec3f*>(::operator new(n * sizeof(Vec3f)))) {
    first_touch(p_.get(), n * sizeof(Vec3f));
  }
  Vec3f* data() const { return p_.get(); }

 private:
  struct Free {
    void operator()(Vec3f* p) const { ::operator delete(p); }
  };
  std::unique_ptr<Vec3f, Free> p_;
};

// The filters, on displacements D from the original positions o (the mesh's): the smoothed
// position is o + D. Every update rule is rewritten for D with the umbrella vector of the original
// positions, L0_i = avg_j (o_j - o_i), so the state stays small (a fraction of a voxel, at most a
// few millimetres for the sinc's intermediate terms) and float keeps it to ~1e-7 of its size:
// after 20 sinc sweeps the positions differ from a computation in double by less than the
// rounding of the final float coordinates (bench/bench_smoothing.cpp's input: 1 ulp at most, in
// under 1 % of the vertices). Every sweep writes every vertex (vertices without neighbours get
// D = 0), reading the previous buffer only.
template <class Index>
class Smoother {
 public:
  Smoother(const VertexRows<Index>& graph, const Vec3f* original, Ticker& ticker)
      : g_(graph), o_(original), n_(graph.offsets.size() - 1), ticker_(ticker) {}

  // Laplacian steps p' = p + f L(p), one per factor: D' = D + f avg_j (o_j - o_i + D_j - D_i).
  // Jacobi: d and scratch swap (the result ends in d). `per_tick` factors make one iteration.
  void laplacian(const std::vector<double>& factors, size_t per_tick, Vec3f*& d, Vec3f*& scratch) {
    for (size_t s = 0; s < factors.size(); ++s) {
      if (s % per_tick == 0) ticker_.begin();
      const float f = static_cast<float>(factors[s]);
      const Vec3f* in = d;
      Vec3f* out = scratch;
      const bool first = s == 0;
      for_each_vertex(n_, [&](size_t i) {
        const Index* j = g_.begin(i);
        const Index* end = g_.end(i);
        if (j == end) {
          out[i] = Vec3f{};
          return;
        }
        const Vec3f oi = o_[i];
        Vec3f sum{};
        if (first) {
          for (; j != end; ++j) sum = add(sum, sub(o_[*j], oi));
          out[i] = mul(f / float(end - g_.begin(i)), sum);
        } else {
          const Vec3f di = in[i];
          for (; j != end; ++j) sum = add(sum, add(sub(o_[*j], oi), in[*j]));
          out[i] = add(di, mul(f, sub(mul(1.0f / float(end - g_.begin(i)), sum), di)));
        }
      });
      std::swap(d, scratch);
      if (s % per_tick == per_tick - 1) ticker_.end();
    }
  }

  // HC, simultaneous version (header). With q = o + D the previous positions and
  // lap = avg q_j: b_i = lap_i - (alpha o_i + (1 - alpha) q_i) = L0_i + avg D_j - (1 - alpha) D_i,
  // and p_i - o_i = lap_i - o_i - beta b_i - (1 - beta) avg b_j
  //              = (1 - beta) (b_i - avg b_j) + (1 - alpha) D_i.
  // Two sweeps per iteration, the second in place (vertex i reads its own D_i only). The first
  // iteration's b is L0 itself, and the second sweep leaves b as it is, so the second iteration
  // takes L0 from b (in place: vertex i reads its own b_i) and gathers only D_j, not o_j as well:
  // a third less to read in that sweep. Later iterations recompute L0 from o.
  void hc(int iterations, double alpha, double beta, Vec3f* d, Vec3f* b) {
    const float keep = static_cast<float>(1 - alpha), spread = static_cast<float>(1 - beta);
    for (int it = 0; it < iterations; ++it) {
      ticker_.begin();
      const bool first = it == 0, second = it == 1;
      for_each_vertex(n_, [&](size_t i) {
        const Index* j = g_.begin(i);
        const Index* end = g_.end(i);
        if (j == end) {
          b[i] = Vec3f{};
          if (first) d[i] = Vec3f{};
          return;
        }
        const float inv = 1.0f / float(end - j);
        Vec3f sum{};
        if (first) {
          const Vec3f oi = o_[i];
          for (; j != end; ++j) sum = add(sum, sub(o_[*j], oi));
          b[i] = mul(inv, sum);
        } else if (second) {
          for (; j != end; ++j) sum = add(sum, d[*j]);
          b[i] = sub(add(b[i], mul(inv, sum)), mul(keep, d[i]));
        } else {
          const Vec3f oi = o_[i];
          for (; j != end; ++j) sum = add(sum, add(sub(o_[*j], oi), d[*j]));
          b[i] = sub(mul(inv, sum), mul(keep, d[i]));
        }
      });
      for_each_vertex(n_, [&](size_t i) {
        const Index* j = g_.begin(i);
        const Index* end = g_.end(i);
        if (j == end) return;
        const float inv = 1.0f / float(end - j);
        Vec3f sum{};
        for (; j != end; ++j) sum = add(sum, b[*j]);
        const Vec3f move = mul(spread, sub(b[i], mul(inv, sum)));
        d[i] = first ? move : add(move, mul(keep, d[i]));
      });
      ticker_.end();
    }
  }

  // Windowed sinc, f = sum_{n=0..N} c_n T_n(A) x with A = (I + avg) / 2 = I - K/2, evaluated by
  // Clenshaw's recurrence b_k = c_k x + 2 A b_{k+1} - b_{k+2} (b_{N+1} = b_{N+2} = 0),
  // f = c_0 x + A b_1 - b_2: N sweeps, two buffers, no running sum. In displacements: with
  // beta_k the same recurrence for A = 1 (beta_k = c_k + 2 beta_{k+1} - beta_{k+2}) and
  // d_k = b_k - beta_k x,
  //   d_k = (d_{k+1} + avg d_{k+1}) - d_{k+2} + beta_{k+1} L0     (d_N = 0, d_{N-1} = c_N L0)
  //   f = F x + (d_1 + avg d_1) / 2 - d_2 + (beta_1 / 2) L0,      F = sum c_n = f(0),
  // where x is the position relative to the bounding-box centre (F != 1 scales about it, as
  // VTK's normalised coordinates do). Returns F; d receives f - F x, the displacement from o
  // apart from the scaling. l0 is scratch for L0.
  double sinc(const std::vector<double>& c, Vec3f*& d, Vec3f*& scratch, Vec3f* l0) {
    const int n = static_cast<int>(c.size()) - 1;
    std::vector<double> beta(n + 3, 0.0);
    for (int k = n; k >= 1; --k) beta[k] = c[k] + 2 * beta[k + 1] - beta[k + 2];
    double gain = 0;
    for (double x : c) gain += x;
    // cur = d_{k+1}, prev = d_{k+2}, starting at k = N - 2.
    Vec3f* cur = d;
    Vec3f* prev = scratch;
    const float c_n = n >= 2 ? static_cast<float>(c[n]) : 0.0f;
    ticker_.begin();
    for_each_vertex(n_, [&](size_t i) {
      const Index* j = g_.begin(i);
      const Index* end = g_.end(i);
      prev[i] = Vec3f{};
      if (j == end) {
        l0[i] = cur[i] = Vec3f{};
        return;
      }
      const Vec3f oi = o_[i];
      const float inv = 1.0f / float(end - j);
      Vec3f sum{};
      for (; j != end; ++j) sum = add(sum, sub(o_[*j], oi));
      l0[i] = mul(inv, sum);
      cur[i] = mul(c_n, l0[i]);
    });
    ticker_.end();
    // x_i + avg_j x_j - y_i + w z_i, scaled by s, for vertex i.
    auto sweep = [&](const Vec3f* x, Vec3f* y, float w, float s) {
      for_each_vertex(n_, [&](size_t i) {
        const Index* j = g_.begin(i);
        const Index* end = g_.end(i);
        if (j == end) {
          y[i] = Vec3f{};
          return;
        }
        const float inv = 1.0f / float(end - j);
        Vec3f sum{};
        for (; j != end; ++j) sum = add(sum, x[*j]);
        y[i] = add(sub(mul(s, add(x[i], mul(inv, sum))), y[i]), mul(w, l0[i]));
      });
    };
    for (int k = n - 2; k >= 1; --k) {
      ticker_.begin();
      sweep(cur, prev, static_cast<float>(beta[k + 1]), 1.0f);
      std::swap(cur, prev);
      ticker_.end();
    }
    if (n >= 2) ticker_.begin();
    sweep(cur, prev, static_cast<float>(0.5 * beta[1]), 0.5f);
    if (n >= 2) ticker_.end();
    d = prev;  // the result
    scratch = cur;
    return gain;
  }

 private:
  const VertexRows<Index>& g_;
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
template <class Index, class Original, class Smoothed>
Restoration restore_volume(const Adjacency<Index>& adj, const std::vector<uint32_t>& idx,
                           Original&& original, Smoothed&& smoothed, size_t nv, Vec3f* normal) {
  const size_t nt = idx.size() / 3;
  // One pass for the normals, one over the triangles for both volumes and the cubic (the
  // normals are wasted only in the rare cases that return early).
  for_each_vertex(nv, [&](size_t i) {
    const Vec3d n = adj.area_normal(idx, i, smoothed);
    const double length = norm(n);
    normal[i] = length > 0 && std::isfinite(length) ? to_float((1.0 / length) * n) : Vec3f{};
  });
  const VolumeCubic k = block_sum<VolumeCubic>(nt, [&](size_t t0, size_t t1) {
    VolumeCubic s;
    for (size_t t = t0; t < t1; ++t) {
      const uint32_t* x = &idx[3 * t];
      s.original += dot(original(x[0]), cross(original(x[1]), original(x[2])));
      const Vec3d a = smoothed(x[0]), b = smoothed(x[1]), c = smoothed(x[2]);
      const Vec3d na = to_d(normal[x[0]]), nb = to_d(normal[x[1]]), nc = to_d(normal[x[2]]);
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

template <class Index>
void smooth_with(TriMesh& mesh, const SmoothOptions& options, int iterations, Progress& progress) {
  const size_t nv = mesh.positions.size();
  const std::vector<uint32_t>& idx = mesh.indices;
  const Adjacency<Index> adj = build_adjacency<Index>(idx, nv, true);
  const VertexRows<Index>& graph = adj.graph();
  const Vec3f* o = mesh.positions.data();
  // The centre of the volume sums and of the sinc filter's scaling.
  const Vec3d centre = box_centre(mesh.positions);

  Ticker ticker(progress, iterations);
  Smoother<Index> smoother(graph, o, ticker);
  // Two float triples per vertex (three for the sinc). The mesh's normals are recomputed at the
  // end, so their storage serves as one of them, made here when the mesh has none (the
  // pipeline's meshes, extracted without normals when smoothing follows): less memory, and one
  // buffer fewer whose pages are touched for the first time (0.65-0.85 ms per MB on the 2-core
  // virtual machines: docs/PERFORMANCE.md).
  std::optional<Vec3fBuffer> own_d, own_l0;
  own_d.emplace(nv);
  Vec3f* d = own_d->data();
  resize_zeroed(mesh.normals, nv);
  Vec3f* scratch = mesh.normals.data();
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
      smoother.hc(iterations, options.alpha, options.beta, d, scratch);
      break;
    case SmoothMethod::sinc:
      own_l0.emplace(nv);
      gain = smoother.sinc(
          windowed_sinc_coefficients(iterations, options.pass_band, options.sinc_unit_gain), d,
          scratch, own_l0->data());
      own_l0.reset();
      break;
    case SmoothMethod::none:
      break;
  }
  // Position i relative to the centre: before (original) and after smoothing. The smoothed ones
  // replace the displacements in d, rounded to float once, because the volume restoration reads
  // each many times. The rounding is at most half a float step of the box's half-diagonal
  // (4e-6 mm for a 200 mm box): no more than the final rounding of the world positions for a
  // mesh away from the world origin, and a few nanometres in any case.
  for_each_vertex(nv, [&](size_t i) {
    d[i] = to_float(gain * (to_d(o[i]) - centre) + to_d(d[i]));
  });
  const auto original = [&](size_t i) { return to_d(o[i]) - centre; };
  const auto smoothed = [&](size_t i) { return to_d(d[i]); };
  Restoration r;
  if (options.preserve_volume) r = restore_volume(adj, idx, original, smoothed, nv, scratch);
  if (!r.keep_original) {
    const bool moved = r.delta != 0;
    for_each_vertex(nv, [&](size_t i) {
      if (graph.size(i) == 0) return;
      Vec3d p = centre + to_d(d[i]);
      if (moved) p = p + r.delta * to_d(scratch[i]);
      mesh.positions[i] = to_float(p);
    });
  }
  own_d.reset();
  write_normals(mesh, adj);
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
  if (mesh_rows_fit_32(mesh.indices.size())) {
    write_normals(mesh, build_adjacency<uint32_t>(mesh.indices, mesh.positions.size(), false));
  } else {
    write_normals(mesh, build_adjacency<uint64_t>(mesh.indices, mesh.positions.size(), false));
  }
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
  if (mesh_rows_fit_32(mesh.indices.size())) {
    smooth_with<uint32_t>(mesh, options, iterations, progress);
  } else {
    smooth_with<uint64_t>(mesh, options, iterations, progress);
  }
}

}  // namespace segmesh
