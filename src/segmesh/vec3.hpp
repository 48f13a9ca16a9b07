// Tiny fixed-size vector and matrix helpers for geometry code. Plain aggregates, no hidden state.
#pragma once

#include <array>
#include <cmath>

namespace segmesh {

struct Vec3f {
  float x = 0, y = 0, z = 0;
};

struct Vec3d {
  double x = 0, y = 0, z = 0;
};

inline Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3d operator*(double s, Vec3d a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3d cross(Vec3d a, Vec3d b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double norm(Vec3d a) { return std::sqrt(dot(a, a)); }
inline Vec3d to_double(Vec3f a) { return {a.x, a.y, a.z}; }
inline Vec3f to_float(Vec3d a) {
  return {static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)};
}

// Row-major 3x3 matrix: m[3 * row + col].
using Mat3d = std::array<double, 9>;

inline constexpr Mat3d identity3() { return {1, 0, 0, 0, 1, 0, 0, 0, 1}; }
inline Vec3d operator*(const Mat3d& m, Vec3d v) {
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
          m[6] * v.x + m[7] * v.y + m[8] * v.z};
}
inline double determinant(const Mat3d& m) {
  return m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
         m[2] * (m[3] * m[7] - m[4] * m[6]);
}

}  // namespace segmesh
