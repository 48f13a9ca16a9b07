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

}  // namespace segmesh
