// Transform: a column-major 4x4 matrix of doubles (t[4 * column + row], the layout of glTF and
// OpenGL), the rigid placement a Part carries on top of its world coordinates (a glTF node, a
// part moved in the viewer), and the operations on it that readers, writers, the renderer and the
// viewer share.
#pragma once

#include <array>

#include "segmesh/vec3.hpp"

namespace segmesh {

using Transform = std::array<double, 16>;

inline constexpr Transform identity_transform() {
  return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
}

inline bool is_identity(const Transform& t) { return t == identity_transform(); }

// a * b: b applied first.
Transform multiply(const Transform& a, const Transform& b);

// The point p with w = 1 through t's upper three rows (t affine: the bottom row is ignored).
Vec3d transform_point(const Transform& t, Vec3d p);

// The direction d (w = 0) through t's upper 3x3.
Vec3d transform_direction(const Transform& t, Vec3d d);

// The determinant of t's upper 3x3 (negative for a mirroring transform).
double linear_determinant(const Transform& t);

// A normal through the inverse transpose of t's upper 3x3, unit length (zero stays zero); the
// determinant's sign is kept, so outward normals stay outward under a mirror as well.
Vec3d transform_normal(const Transform& t, Vec3d n);

}  // namespace segmesh
