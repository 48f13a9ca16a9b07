// Where the iso-surface crosses a cell edge, and the field gradient there: the Hermite data that
// Marching Cubes places its vertices with and Dual Contouring builds its QEFs from.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "segmesh/gradient.hpp"
#include "segmesh/vec3.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

// A crossing is never placed closer than this fraction of the edge length to the edge's ends, so a
// corner value equal to the iso value (integer CT at an integer iso) never collapses vertices
// into zero-area triangles.
inline constexpr double kMinEdgeFraction = 0.01;

// Linear interpolation of the crossing between values v0 and v1 (the thesis's Eq. 25 with its
// sign slip corrected: t = (iso - v0) / (v1 - v0)), kept kMinEdgeFraction away from the ends.
inline double edge_fraction(double v0, double v1, double iso) {
  const double t = (iso - v0) / (v1 - v0);
  if (!std::isfinite(t)) return 0.5;
  return std::clamp(t, kMinEdgeFraction, 1.0 - kMinEdgeFraction);
}

struct EdgeCrossing {
  Vec3d index_point;     // in the field's index space
  Vec3d index_gradient;  // gradient interpolated along the edge, index space (per voxel step)
  double t = 0.5;
};

// Where the iso-surface crosses the edge from grid point (i, j, k) one step along `axis`, without
// the gradient (index_gradient left zero).
template <class T>
EdgeCrossing edge_point(const Volume<T>& f, int64_t i, int64_t j, int64_t k, int axis, double iso) {
  const int64_t i1 = i + (axis == 0), j1 = j + (axis == 1), k1 = k + (axis == 2);
  EdgeCrossing c;
  c.t = edge_fraction(static_cast<double>(f.at(i, j, k)), static_cast<double>(f.at(i1, j1, k1)),
                      iso);
  c.index_point = {i + c.t * (i1 - i), j + c.t * (j1 - j), k + c.t * (k1 - k)};
  return c;
}

// The crossing on the edge from grid point (i, j, k) one step along `axis`, with the gradient.
template <class T>
EdgeCrossing edge_crossing(const Volume<T>& f, int64_t i, int64_t j, int64_t k, int axis,
                           double iso, NormalMethod normals) {
  EdgeCrossing c = edge_point(f, i, j, k, axis, iso);
  const int64_t i1 = i + (axis == 0), j1 = j + (axis == 1), k1 = k + (axis == 2);
  c.index_gradient = (1 - c.t) * gradient(f, i, j, k, normals) + c.t * gradient(f, i1, j1, k1, normals);
  return c;
}

// Higher-order Hermite data, what Dual Contouring uses on grey-value fields (DcHermite::cubic).
//
// The crossing is the root in the edge of the Catmull-Rom cubic through the four values along its
// line (the edge's two ends and one beyond each, the border value repeated outside the volume):
// exact where the field is a cubic along the edge, where linear interpolation is exact only for a
// linear one. Near a feature a signed distance field is not smooth (its gradient jumps across the
// medial surface inside and turns around an edge outside), and a central difference that
// straddles the jump mixes the normals of two faces. So each end's derivative across the edge is
// taken ENO-style (essentially non-oscillatory, Harten and Osher 1987): the central difference,
// unless a one-sided difference has a smaller second difference (its stencil does not cross the
// kink), and then that one-sided one. Along the edge the derivative is the secant between the
// ends, which never reads beyond the edge. Sobel normals keep the interpolated Sobel gradient.
namespace detail {

// Where the Catmull-Rom segment crosses iso, given that v0 and v1 lie on either side of it (one
// may equal it: a value equal to iso is inside, as everywhere): Newton's method from the linear estimate, kept inside a bracket of the root (a step that
// leaves it bisects instead), to 1e-10 of the edge; kept kMinEdgeFraction away from the ends as
// edge_fraction is.
inline double cubic_edge_fraction(double vm, double v0, double v1, double v2, double iso) {
  const double linear = edge_fraction(v0, v1, iso);
  if (!std::isfinite(vm) || !std::isfinite(v2)) return linear;
  // The cubic as a + t (b + t (c + t d)), minus iso.
  const double m0 = (v1 - vm) / 2, m1 = (v2 - v0) / 2;
  const double a = v0 - iso, b = m0, c = 3 * (v1 - v0) - 2 * m0 - m1, d = 2 * (v0 - v1) + m0 + m1;
  const bool end_below = v1 < iso;  // a point on the side of v1 is on the root's far side
  double lo = 0, hi = 1, t = linear;
  for (int it = 0; it < 60; ++it) {
    const double g = a + t * (b + t * (c + t * d)), slope = b + t * (2 * c + 3 * t * d);
    if ((g < 0) != end_below) {
      lo = t;
    } else {
      hi = t;
    }
    double next = t - g / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - t) < 1e-10;
    t = next;
    if (done) break;
  }
  return std::clamp(t, kMinEdgeFraction, 1.0 - kMinEdgeFraction);
}

// The derivative across an edge at grid point p (values vm, v0, vp at -1, 0, +1 along the axis,
// vmm and vpp at -2 and +2): central, unless a one-sided stencil is smoother.
inline double eno_derivative(double vmm, double vm, double v0, double vp, double vpp) {
  const double back = std::abs(v0 - 2 * vm + vmm), centre = std::abs(vp - 2 * v0 + vm),
               ahead = std::abs(vpp - 2 * vp + v0);
  if (centre <= std::min(back, ahead)) return (vp - vm) / 2;
  return back < ahead ? v0 - vm : vp - v0;
}

template <class T>
double eno_derivative_at(const Volume<T>& f, int64_t i, int64_t j, int64_t k, int axis) {
  const int64_t di = axis == 0, dj = axis == 1, dk = axis == 2;
  auto at = [&](int64_t s) { return voxel_clamped(f, i + s * di, j + s * dj, k + s * dk); };
  return eno_derivative(at(-2), at(-1), at(0), at(1), at(2));
}

}  // namespace detail

// The crossing on the edge from grid point (i, j, k) one step along `axis`, with the gradient,
// from the higher-order interpolation above.
template <class T>
EdgeCrossing cubic_edge_crossing(const Volume<T>& f, int64_t i, int64_t j, int64_t k, int axis,
                                 double iso, NormalMethod normals) {
  const int64_t di = axis == 0, dj = axis == 1, dk = axis == 2;
  auto at = [&](int64_t s) { return detail::voxel_clamped(f, i + s * di, j + s * dj, k + s * dk); };
  const double v0 = at(0), v1 = at(1);
  EdgeCrossing c;
  c.t = detail::cubic_edge_fraction(at(-1), v0, v1, at(2), iso);
  c.index_point = {i + c.t * di, j + c.t * dj, k + c.t * dk};
  if (normals == NormalMethod::sobel) {
    c.index_gradient =
        (1 - c.t) * gradient(f, i, j, k, normals) + c.t * gradient(f, i + di, j + dj, k + dk, normals);
    return c;
  }
  double g[3];
  for (int a = 0; a < 3; ++a) {
    g[a] = a == axis ? v1 - v0
                     : (1 - c.t) * detail::eno_derivative_at(f, i, j, k, a) +
                           c.t * detail::eno_derivative_at(f, i + di, j + dj, k + dk, a);
  }
  c.index_gradient = {g[0], g[1], g[2]};
  return c;
}

}  // namespace segmesh
