// Mat4: a column-major 4x4 matrix of doubles (the layout of segmesh::Transform and of OpenGL), and
// the few operations the camera and the renderer need on top of transform.hpp's. Plain functions on plain arrays.
#pragma once

#include <array>

#include "segmesh/scene.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh::render {

// m[4 * column + row]; the same type as segmesh::Transform.
using Mat4 = Transform;

inline constexpr Mat4 identity4() { return identity_transform(); }

Mat4 operator*(const Mat4& a, const Mat4& b);

// Points and directions through a Mat4: segmesh::transform_point and transform_direction
// (transform.hpp).

// The inverse of m; the zero matrix when m is singular.
Mat4 inverse(const Mat4& m);

// The inverse transpose of m's upper 3x3 (what normals transform by), as a column-major 3x3.
std::array<double, 9> normal_matrix(const Mat4& m);

// A view matrix: the world seen from `eye`, looking along `forward`, `up` roughly up (both unit).
Mat4 look_along(Vec3d eye, Vec3d forward, Vec3d up);

// The OpenGL perspective projection (depth -1 at near, +1 at far).
Mat4 perspective(double fov_y_rad, double aspect, double near, double far);

// Unit vector of d (d itself when it has zero length).
Vec3d normalized(Vec3d d);

}  // namespace segmesh::render
