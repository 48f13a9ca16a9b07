// Garland and Heckbert's quadric error: a symmetric 4x4 matrix whose value at a point is a sum of
// squared (weighted) distances to planes, its minimiser, and that error as a distance
// (decimation.hpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include "segmesh/vec3.hpp"

namespace segmesh {

// A symmetric 4x4 quadric: xx xy xz xd yy yz yd zz zd dd.
struct Quadric {
  double q[10] = {};
  Quadric& operator+=(const Quadric& o) {
    for (int i = 0; i < 10; ++i) q[i] += o.q[i];
    return *this;
  }
};

inline Quadric plane_quadric(Vec3d n, double d) {
  return {{n.x * n.x, n.x * n.y, n.x * n.z, n.x * d, n.y * n.y, n.y * n.z, n.y * d, n.z * n.z,
           n.z * d, d * d}};
}

inline double evaluate(const Quadric& Q, Vec3d p) {
  const double* q = Q.q;
  return q[0] * p.x * p.x + 2 * q[1] * p.x * p.y + 2 * q[2] * p.x * p.z + 2 * q[3] * p.x +
         q[4] * p.y * p.y + 2 * q[5] * p.y * p.z + 2 * q[6] * p.y + q[7] * p.z * p.z +
         2 * q[8] * p.z + q[9];
}

// The error as a distance: the root of the summed squared plane distances.
inline double cost_mm(const Quadric& Q, Vec3d p) {
  return std::sqrt(std::max(0.0, evaluate(Q, p)));
}

// The minimiser of Q when it is well conditioned.
inline std::optional<Vec3d> optimum(const Quadric& Q) {
  const double* q = Q.q;
  const Mat3d a{q[0], q[1], q[2], q[1], q[4], q[5], q[2], q[5], q[7]};
  const double det = determinant(a);
  // Relative to the matrix's scale: a plane-only (flat) or line-only (crease) quadric is singular.
  const double scale = q[0] + q[4] + q[7];
  if (!(std::abs(det) > 1e-6 * scale * scale * scale)) return std::nullopt;
  const Vec3d b{-q[3], -q[6], -q[8]};
  // Cramer's rule.
  auto col = [&](int c) {
    Mat3d m = a;
    m[size_t(c)] = b.x;
    m[size_t(3 + c)] = b.y;
    m[size_t(6 + c)] = b.z;
    return determinant(m) / det;
  };
  return Vec3d{col(0), col(1), col(2)};
}

}  // namespace segmesh
