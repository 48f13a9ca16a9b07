#include "segmesh/smoothing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

// Vertices per task: enough work to amortise scheduling, small enough to balance two to a few
// dozen cores. Results never depend on it.
constexpr size_t kVertexGrain = 2048;
constexpr size_t kTriangleGrain = 4096;

template <class F>
void for_each_vertex(size_t n, F&& body) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) body(i);
                    });
}

// Compressed rows: row i is entries[offsets[i] .. offsets[i + 1]).
struct Rows {
  std::vector<size_t> offsets;
  std::vector<uint32_t> entries;

  size_t size(size_t i) const { return offsets[i + 1] - offsets[i]; }
  const uint32_t* begin(size_t i) const { return entries.data() + offsets[i]; }
  const uint32_t* end(size_t i) const { return entries.data() + offsets[i + 1]; }
};

// offsets[i] = sum of counts[0 .. i), offsets[n] = the total.
std::vector<size_t> prefix_offsets(const std::vector<uint32_t>& counts) {
  std::vector<size_t> offsets(counts.size() + 1);
  size_t sum = 0;
  for (size_t i = 0; i < counts.size(); ++i) {
    offsets[i] = sum;
    sum += counts[i];
  }
  offsets[counts.size()] = sum;
  return offsets;
}

// Vertex -> the triangles using it, each row in increasing triangle order (a triangle repeating a
// vertex appears once per corner). Counted and filled in parallel with atomic counters; the fill
// order within a row depends on the schedule, so every row is sorted afterwards, which makes the
// result independent of it.
Rows vertex_triangles(const TriMesh& mesh) {
  const size_t nv = mesh.positions.size();
  const size_t nt = mesh.triangle_count();
  const auto& idx = mesh.indices;
  std::vector<uint32_t> counts(nv, 0);
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, nt, kTriangleGrain), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t h = 3 * r.begin(); h != 3 * r.end(); ++h) {
          assert(idx[h] < nv);
          std::atomic_ref<uint32_t>(counts[idx[h]]).fetch_add(1, std::memory_order_relaxed);
        }
      });
  Rows rows;
  rows.offsets = prefix_offsets(counts);
  rows.entries.resize(rows.offsets[nv]);
  std::vector<size_t> cursor(rows.offsets.begin(), rows.offsets.end() - 1);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nt, kTriangleGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t t = r.begin(); t != r.end(); ++t)
                        for (int c = 0; c < 3; ++c) {
                          const size_t slot = std::atomic_ref<size_t>(cursor[idx[3 * t + c]])
                                                  .fetch_add(1, std::memory_order_relaxed);
                          rows.entries[slot] = static_cast<uint32_t>(t);
                        }
                    });
  for_each_vertex(nv, [&](size_t i) {
    std::sort(rows.entries.begin() + static_cast<ptrdiff_t>(rows.offsets[i]),
              rows.entries.begin() + static_cast<ptrdiff_t>(rows.offsets[i + 1]));
  });
  return rows;
}

// Vertex -> its edge neighbours: the other corners of its triangles, each once, sorted, itself
// excluded. Two parallel passes over the vertices (count, then fill), each gathering a vertex's
// corners into a per-task buffer; deterministic because each row is a sorted set.
Rows vertex_neighbours(const TriMesh& mesh, const Rows& triangles) {
  const size_t nv = mesh.positions.size();
  const auto& idx = mesh.indices;
  auto gather = [&](size_t i, std::vector<uint32_t>& buffer) {
    buffer.clear();
    for (const uint32_t* t = triangles.begin(i); t != triangles.end(i); ++t)
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = idx[3 * size_t{*t} + c];
        if (v != i) buffer.push_back(v);
      }
    std::sort(buffer.begin(), buffer.end());
    buffer.erase(std::unique(buffer.begin(), buffer.end()), buffer.end());
  };
  std::vector<uint32_t> counts(nv);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      std::vector<uint32_t> buffer;
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        gather(i, buffer);
                        counts[i] = static_cast<uint32_t>(buffer.size());
                      }
                    });
  Rows rows;
  rows.offsets = prefix_offsets(counts);
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

// The average of the neighbours' positions; the caller makes sure the row is not empty.
Vec3d neighbour_average(const Rows& nb, size_t i, const std::vector<Vec3d>& p) {
  Vec3d sum{};
  for (const uint32_t* j = nb.begin(i); j != nb.end(i); ++j) sum = sum + p[*j];
  return (1.0 / double(nb.size(i))) * sum;
}

// out = in + factor * L(in); vertices without neighbours are copied.
void laplacian_sweep(const Rows& nb, const std::vector<Vec3d>& in, std::vector<Vec3d>& out,
                     double factor) {
  for_each_vertex(in.size(), [&](size_t i) {
    out[i] = nb.size(i) == 0 ? in[i] : in[i] + factor * (neighbour_average(nb, i, in) - in[i]);
  });
}

void compute_normals(TriMesh& mesh, const Rows& triangles) {
  const auto& idx = mesh.indices;
  const auto& pos = mesh.positions;
  mesh.normals.resize(pos.size());
  for_each_vertex(pos.size(), [&](size_t i) {
    Vec3d sum{};
    for (const uint32_t* t = triangles.begin(i); t != triangles.end(i); ++t) {
      const Vec3d a = to_double(pos[idx[3 * size_t{*t}]]);
      const Vec3d b = to_double(pos[idx[3 * size_t{*t} + 1]]);
      const Vec3d c = to_double(pos[idx[3 * size_t{*t} + 2]]);
      sum = sum + cross(b - a, c - a);
    }
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

// The smoothing proper, on double positions relative to a centre; returns the new positions.
class Smoother {
 public:
  Smoother(const Rows& neighbours, std::vector<Vec3d> start, int iterations, Progress& progress)
      : nb_(neighbours), p_(std::move(start)), iterations_(iterations), progress_(progress) {}

  std::vector<Vec3d> laplacian(double lambda) {
    std::vector<Vec3d> q(p_.size());
    for (int it = 0; it < iterations_; ++it) {
      begin_iteration();
      laplacian_sweep(nb_, p_, q, lambda);
      p_.swap(q);
      end_iteration(it);
    }
    return std::move(p_);
  }

  std::vector<Vec3d> taubin(double lambda, double mu) {
    std::vector<Vec3d> q(p_.size());
    for (int it = 0; it < iterations_; ++it) {
      begin_iteration();
      laplacian_sweep(nb_, p_, q, lambda);
      laplacian_sweep(nb_, q, p_, mu);
      end_iteration(it);
    }
    return std::move(p_);
  }

  // Vollmer, Mencl and Mueller's HC, simultaneous version (header comment). p_ holds q, the
  // previous positions; original(i) gives o_i, recomputed rather than stored.
  template <class Original>
  std::vector<Vec3d> hc(double alpha, double beta, Original&& original) {
    std::vector<Vec3d> lap(p_.size()), b(p_.size());
    for (int it = 0; it < iterations_; ++it) {
      begin_iteration();
      for_each_vertex(p_.size(), [&](size_t i) {
        if (nb_.size(i) == 0) {
          lap[i] = p_[i];
          b[i] = Vec3d{};
          return;
        }
        lap[i] = neighbour_average(nb_, i, p_);
        b[i] = lap[i] - (alpha * original(i) + (1 - alpha) * p_[i]);
      });
      for_each_vertex(p_.size(), [&](size_t i) {
        if (nb_.size(i) == 0) {
          p_[i] = lap[i];
          return;
        }
        p_[i] = lap[i] - (beta * b[i] + (1 - beta) * neighbour_average(nb_, i, b));
      });
      end_iteration(it);
    }
    return std::move(p_);
  }

  // Windowed sinc by the Chebyshev recursion (header comment). p_ holds the normalised start.
  std::vector<Vec3d> sinc(double pass_band, bool unit_gain) {
    const std::vector<double> c = windowed_sinc_coefficients(iterations_, pass_band, unit_gain);
    // x0 = T_{n-1}(I - K/2) p, x1 = T_n(I - K/2) p, sum = sum_{m <= n} c_m T_m(I - K/2) p.
    std::vector<Vec3d> x0 = std::move(p_), x1(x0.size()), sum(x0.size());
    begin_iteration();
    for_each_vertex(x0.size(), [&](size_t i) {
      x1[i] = nb_.size(i) == 0 ? x0[i] : 0.5 * (x0[i] + neighbour_average(nb_, i, x0));
      sum[i] = c[0] * x0[i] + c[1] * x1[i];
    });
    end_iteration(0);
    for (int n = 1; n < iterations_; ++n) {
      begin_iteration();
      // x_{n+1} = 2 (I - K/2) x_n - x_{n-1} = x_n + avg(x_n) - x_{n-1}, written over x_{n-1}:
      // vertex i reads its own x_{n-1} only.
      for_each_vertex(x0.size(), [&](size_t i) {
        if (nb_.size(i) == 0) return;
        x0[i] = x1[i] + neighbour_average(nb_, i, x1) - x0[i];
        sum[i] = sum[i] + c[n + 1] * x0[i];
      });
      x0.swap(x1);
      end_iteration(n);
    }
    return sum;
  }

 private:
  void begin_iteration() { throw_if_cancelled(progress_); }
  void end_iteration(int it) { progress_.update(double(it + 1) / double(iterations_)); }

  const Rows& nb_;
  std::vector<Vec3d> p_;
  int iterations_;
  Progress& progress_;
};

double enclosed_volume(const std::vector<uint32_t>& idx, const std::vector<Vec3d>& p) {
  double v6 = 0;
  for (size_t t = 0; t < idx.size(); t += 3) v6 += dot(p[idx[t]], cross(p[idx[t + 1]], p[idx[t + 2]]));
  return v6 / 6;
}

// Gives the smoothed positions back the enclosed volume of the original ones: every vertex moves
// along its (area-weighted) normal by the offset delta = (V0 - V) / area, three times (the first
// step is exact to first order). A part that smoothing nearly erased (below a quarter of its
// volume: specks of a few voxels) keeps its original positions instead.
template <class Original>
void restore_volume(const std::vector<uint32_t>& idx, Original&& original, std::vector<Vec3d>& p) {
  std::vector<Vec3d> start(p.size());
  for (size_t i = 0; i < p.size(); ++i) start[i] = original(i);
  const double target = enclosed_volume(idx, start);
  if (!(target > 0)) return;  // not a closed outward-wound surface: nothing to restore
  double volume = enclosed_volume(idx, p);
  if (volume < 0.25 * target) {
    p = std::move(start);
    return;
  }
  std::vector<Vec3d> normal(p.size());
  for (int step = 0; step < 3 && std::abs(volume - target) > 1e-9 * target; ++step) {
    std::fill(normal.begin(), normal.end(), Vec3d{});
    double area = 0;
    for (size_t t = 0; t < idx.size(); t += 3) {
      const Vec3d a = p[idx[t]];
      const Vec3d n = cross(p[idx[t + 1]] - a, p[idx[t + 2]] - a);
      area += 0.5 * norm(n);
      for (int k = 0; k < 3; ++k) normal[idx[t + k]] = normal[idx[t + k]] + n;
    }
    if (!(area > 0)) return;
    const double delta = (target - volume) / area;
    for (size_t i = 0; i < p.size(); ++i) {
      const double len = norm(normal[i]);
      if (len > 0) p[i] = p[i] + (delta / len) * normal[i];
    }
    volume = enclosed_volume(idx, p);
  }
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
  compute_normals(mesh, vertex_triangles(mesh));
}

void smooth_mesh(TriMesh& mesh, const SmoothOptions& options, Progress& progress) {
  check_options(options);
  if (options.method == SmoothMethod::none) return;
  const size_t nv = mesh.positions.size();
  if (nv == 0) {
    mesh.normals.clear();
    return;
  }
  const int iterations =
      options.iterations > 0 ? options.iterations : default_smooth_iterations(options.method);
  const Rows triangles = vertex_triangles(mesh);
  const Rows neighbours = vertex_neighbours(mesh, triangles);

  // The frame the smoother works in: centred on the centroid (windowed sinc: on the bounding box
  // centre, scaled by its diagonal, as VTK's NormalizeCoordinates).
  Vec3d centre{};
  double scale = 1;
  if (options.method == SmoothMethod::sinc) {
    Vec3d lo = to_double(mesh.positions[0]), hi = lo;
    for (const Vec3f& p : mesh.positions) {
      lo = {std::min(lo.x, double(p.x)), std::min(lo.y, double(p.y)), std::min(lo.z, double(p.z))};
      hi = {std::max(hi.x, double(p.x)), std::max(hi.y, double(p.y)), std::max(hi.z, double(p.z))};
    }
    centre = 0.5 * (lo + hi);
    const double diagonal = norm(hi - lo);
    if (diagonal > 0) scale = diagonal;
  } else {
    for (const Vec3f& p : mesh.positions) centre = centre + to_double(p);
    centre = (1.0 / double(nv)) * centre;
  }
  const auto original = [&](size_t i) {
    return (1.0 / scale) * (to_double(mesh.positions[i]) - centre);
  };
  std::vector<Vec3d> start(nv);
  for_each_vertex(nv, [&](size_t i) { start[i] = original(i); });

  Smoother smoother(neighbours, std::move(start), iterations, progress);
  std::vector<Vec3d> result;
  switch (options.method) {
    case SmoothMethod::laplacian:
      result = smoother.laplacian(options.lambda);
      break;
    case SmoothMethod::hc:
      result = smoother.hc(options.alpha, options.beta, original);
      break;
    case SmoothMethod::taubin:
      result = smoother.taubin(options.taubin_lambda, options.taubin_mu);
      break;
    case SmoothMethod::sinc:
      result = smoother.sinc(options.pass_band, options.sinc_unit_gain);
      break;
    case SmoothMethod::none:
      break;
  }
  if (options.preserve_volume) restore_volume(mesh.indices, original, result);
  for_each_vertex(nv, [&](size_t i) {
    if (neighbours.size(i) > 0) mesh.positions[i] = to_float(scale * result[i] + centre);
  });
  compute_normals(mesh, triangles);
}

}  // namespace segmesh
