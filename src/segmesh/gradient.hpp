// Volume gradients for vertex normals: central differences or the 3x3x3 Sobel operator.
//
// Both return the gradient in index space (the change of value per voxel step along each axis);
// Grid::gradient_to_world divides by the spacing and applies the direction, which gives the
// world-space gradient, so normals built from it are right on anisotropic and rotated grids. Outside the volume the border
// value repeats (the callers pad volumes with background, so the repeat is background too).
//
// Sobel: derivative [-1 0 1] / 2 along the axis, smoothing [1 2 1] / 4 on each of the other two
// (the separable kernel, divided by the spacing of the derivative axis in gradient_to_world;
// the thesis's Eq. 5 is garbled in its text). It averages over 27 voxels,
// which gives smoother normals on binary label maps at about four times the cost.
#pragma once

#include <algorithm>
#include <cstdint>

#include "segmesh/vec3.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

enum class NormalMethod { central, sobel };

namespace detail {
template <class T>
inline double voxel_clamped(const Volume<T>& v, int64_t i, int64_t j, int64_t k) {
  const auto& d = v.grid.dims;
  i = std::clamp<int64_t>(i, 0, d[0] - 1);
  j = std::clamp<int64_t>(j, 0, d[1] - 1);
  k = std::clamp<int64_t>(k, 0, d[2] - 1);
  return static_cast<double>(v.voxels[v.grid.index(i, j, k)]);
}
}  // namespace detail

// The gradients from the values around a point: at(di, dj, dk) is the value (double) at offset
// (di, dj, dk), each in -1 .. 1. The volume versions below read voxels through them; Dual
// Contouring reads the bits of a cell's neighbourhood (detail/dc_vertices.cpp).
template <class At>
Vec3d central_gradient_of(At&& at) {
  return {(at(1, 0, 0) - at(-1, 0, 0)) / 2, (at(0, 1, 0) - at(0, -1, 0)) / 2,
          (at(0, 0, 1) - at(0, 0, -1)) / 2};
}

template <class At>
Vec3d sobel_gradient_of(At&& at) {
  static constexpr double w[3] = {1, 2, 1};
  double g[3] = {0, 0, 0};
  for (int dk = -1; dk <= 1; ++dk) {
    for (int dj = -1; dj <= 1; ++dj) {
      for (int di = -1; di <= 1; ++di) {
        const double f = at(di, dj, dk);
        g[0] += di * w[dj + 1] * w[dk + 1] * f;
        g[1] += dj * w[di + 1] * w[dk + 1] * f;
        g[2] += dk * w[di + 1] * w[dj + 1] * f;
      }
    }
  }
  return {g[0] / 32, g[1] / 32, g[2] / 32};
}

namespace detail {
// of(at) at voxel (i, j, k) of v: the neighbours read directly inside (every extraction vertex of
// a padded field), clamped to the volume at its border.
template <class T, class Of>
Vec3d volume_gradient(const Volume<T>& v, int64_t i, int64_t j, int64_t k, Of&& of) {
  const auto& d = v.grid.dims;
  if (i > 0 && j > 0 && k > 0 && i + 1 < d[0] && j + 1 < d[1] && k + 1 < d[2]) {
    const T* p = v.voxels.data() + v.grid.index(i, j, k);
    const int64_t sy = d[0], sz = d[0] * d[1];
    return of(
        [&](int di, int dj, int dk) { return static_cast<double>(p[di + dj * sy + dk * sz]); });
  }
  return of([&](int di, int dj, int dk) { return voxel_clamped(v, i + di, j + dj, k + dk); });
}
}  // namespace detail

template <class T>
Vec3d central_gradient(const Volume<T>& v, int64_t i, int64_t j, int64_t k) {
  return detail::volume_gradient(v, i, j, k, [](auto&& at) { return central_gradient_of(at); });
}

template <class T>
Vec3d sobel_gradient(const Volume<T>& v, int64_t i, int64_t j, int64_t k) {
  return detail::volume_gradient(v, i, j, k, [](auto&& at) { return sobel_gradient_of(at); });
}

template <class T>
Vec3d gradient(const Volume<T>& v, int64_t i, int64_t j, int64_t k, NormalMethod method) {
  return method == NormalMethod::sobel ? sobel_gradient(v, i, j, k) : central_gradient(v, i, j, k);
}

}  // namespace segmesh
