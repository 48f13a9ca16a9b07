// Mat3 and the few 3x3 and float conversions the renderer needs on top of mat4.hpp: the upper 3x3
// of a 4x4 matrix, a 3x3 product, and a Mat4 as the floats OpenGL takes.
//
// Why here: the matrices are composed in double precision (the parts' transforms, the view) and
// only the results are handed to the shaders as floats; these helpers are that last step.
// Guarantees: column-major like Mat4 (m[3 * column + row]); plain functions, no OpenGL, no cost
// beyond the arithmetic.
#pragma once

#include <array>

#include "segmesh_render/mat4.hpp"

namespace segmesh::render {

using Mat3 = std::array<double, 9>;  // column-major, as normal_matrix returns it

inline std::array<float, 16> to_float(const Mat4& m) {
  std::array<float, 16> f{};
  for (int i = 0; i < 16; ++i) f[i] = static_cast<float>(m[i]);
  return f;
}

inline Mat3 upper3(const Mat4& m) {
  return {m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]};
}

inline Mat3 mul3(const Mat3& a, const Mat3& b) {
  Mat3 r{};
  for (int c = 0; c < 3; ++c)
    for (int row = 0; row < 3; ++row)
      for (int k = 0; k < 3; ++k) r[3 * c + row] += a[3 * k + row] * b[3 * c + k];
  return r;
}

}  // namespace segmesh::render
