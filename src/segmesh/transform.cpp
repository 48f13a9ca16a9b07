#include "segmesh/transform.hpp"

namespace segmesh {

Transform multiply(const Transform& a, const Transform& b) {
  Transform c{};
  for (int col = 0; col < 4; ++col) {
    for (int row = 0; row < 4; ++row) {
      double s = 0;
      for (int k = 0; k < 4; ++k) s += a[4 * k + row] * b[4 * col + k];
      c[4 * col + row] = s;
    }
  }
  return c;
}

Vec3d transform_point(const Transform& t, Vec3d p) {
  return {t[0] * p.x + t[4] * p.y + t[8] * p.z + t[12],
          t[1] * p.x + t[5] * p.y + t[9] * p.z + t[13],
          t[2] * p.x + t[6] * p.y + t[10] * p.z + t[14]};
}

Vec3d transform_direction(const Transform& t, Vec3d d) {
  return {t[0] * d.x + t[4] * d.y + t[8] * d.z, t[1] * d.x + t[5] * d.y + t[9] * d.z,
          t[2] * d.x + t[6] * d.y + t[10] * d.z};
}

double linear_determinant(const Transform& t) {
  const Mat3d m{t[0], t[4], t[8], t[1], t[5], t[9], t[2], t[6], t[10]};
  return determinant(m);
}

Vec3d transform_normal(const Transform& t, Vec3d n) {
  // Rows of the inverse transpose are the cofactors of the linear part; the determinant's scale
  // drops out in the normalisation, its sign is kept so normals still point outwards.
  const Vec3d c0{t[0], t[1], t[2]}, c1{t[4], t[5], t[6]}, c2{t[8], t[9], t[10]};
  const Vec3d r0 = cross(c1, c2), r1 = cross(c2, c0), r2 = cross(c0, c1);
  const double det = dot(c0, r0);
  Vec3d out = (det < 0 ? -1.0 : 1.0) * (n.x * r0 + n.y * r1 + n.z * r2);
  const double len = norm(out);
  return len > 0 ? (1.0 / len) * out : out;
}

}  // namespace segmesh
