#include "segmesh/smoothing.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <new>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "segmesh/detail/float4.hpp"
#include "segmesh/detail/smoothing_filters.hpp"
#include "segmesh/detail/smoothing_sweeps.hpp"
#include "segmesh/detail/volume_restoration.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

void smooth_with(TriMesh& mesh, const SmoothOptions& options, int iterations, Progress& progress) {
  const size_t nv = mesh.positions.size();
  const std::vector<uint32_t>& idx = mesh.indices;
  const Triangles triangles{idx.data(), triangle_chunks(idx)};
  const Vec3f* o = mesh.positions.data();
  // The centre of the volume sums and of the sinc filter's scaling (not needed otherwise).
  const bool centred = options.method == SmoothMethod::sinc || options.preserve_volume;
  const Vec3d centre = centred ? box_centre(mesh.positions) : Vec3d{};

  FilterRun run = run_filter(triangles, o, nv, options, iterations, progress);
  F4* d = run.d;
  F4* scratch = run.scratch;
  const double gain = run.gain;
  // The triangle counts ride in the fourth lane of the sinc's L0, of the displacements otherwise.
  const F4* counts = run.counts();
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
    run.own_l0.reset();
    const Restoration r = restore_volume(triangles, idx, o, centre, d, nv, scratch);
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

std::optional<OptionProblem> smooth_options_problem(const SmoothOptions& o) {
  auto problem = [](std::string_view option, std::string rule, double value) {
    char got[32];
    std::snprintf(got, sizeof got, " (got %g)", value);
    return OptionProblem{option, rule + got};
  };
  if (o.iterations < 0) {
    return problem("iterations", "must be 0 (the method's default) or more", o.iterations);
  }
  if (!std::isfinite(o.lambda)) return problem("lambda", "must be a finite number", o.lambda);
  if (!(o.alpha >= 0 && o.alpha <= 1)) return problem("alpha", "must be between 0 and 1", o.alpha);
  if (!(o.beta >= 0 && o.beta <= 1)) return problem("beta", "must be between 0 and 1", o.beta);
  if (!std::isfinite(o.taubin_lambda)) {
    return problem("taubin_lambda", "must be a finite number", o.taubin_lambda);
  }
  if (!std::isfinite(o.taubin_mu)) return problem("taubin_mu", "must be a finite number", o.taubin_mu);
  if (!(o.pass_band > 0 && o.pass_band <= 2)) {
    return problem("pass_band", "must be above 0 and at most 2", o.pass_band);
  }
  return std::nullopt;
}

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
  if (const auto problem = smooth_options_problem(options)) {
    throw std::invalid_argument("smooth_mesh: " + std::string(problem->option) + " " + problem->rule);
  }
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
