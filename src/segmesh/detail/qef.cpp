#include "segmesh/detail/qef.hpp"

#include <algorithm>
#include <cmath>

namespace segmesh {

void Qef::add(Vec3d p, Vec3d n) {
  ata[0] += n.x * n.x;
  ata[1] += n.x * n.y;
  ata[2] += n.x * n.z;
  ata[3] += n.y * n.y;
  ata[4] += n.y * n.z;
  ata[5] += n.z * n.z;
  const double b = dot(n, p);
  atb = atb + b * n;
  btb += b * b;
  point_sum = point_sum + p;
  ++count;
}

void Qef::merge(const Qef& o) {
  for (int i = 0; i < 6; ++i) ata[i] += o.ata[i];
  atb = atb + o.atb;
  btb += o.btb;
  point_sum = point_sum + o.point_sum;
  count += o.count;
}

namespace {
Mat3d full(const std::array<double, 6>& a) {
  return {a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]};
}
}  // namespace

Qef Qef::translated(Vec3d d) const {
  Qef q = *this;
  const Vec3d ad = full(ata) * d;
  // b_i' = n_i . (p_i + d) = b_i + n_i . d
  q.atb = atb + ad;
  q.btb = btb + 2 * dot(d, atb) + dot(d, ad);
  q.point_sum = point_sum + double(count) * d;
  return q;
}

double Qef::error(Vec3d x) const {
  const Vec3d ax = full(ata) * x;
  return std::max(0.0, dot(x, ax) - 2 * dot(x, atb) + btb);
}

Vec3d keep_in_box(Vec3d x, Vec3d mass, Vec3d lo, Vec3d hi) {
  const double xs[3] = {x.x, x.y, x.z}, los[3] = {lo.x, lo.y, lo.z}, his[3] = {hi.x, hi.y, hi.z};
  double ms[3] = {mass.x, mass.y, mass.z};
  for (int a = 0; a < 3; ++a) ms[a] = std::clamp(ms[a], los[a], his[a]);
  double t = 1;
  for (int a = 0; a < 3; ++a) {
    const double d = xs[a] - ms[a];
    if (xs[a] > his[a] && d > 0) t = std::min(t, (his[a] - ms[a]) / d);
    if (xs[a] < los[a] && d < 0) t = std::min(t, (los[a] - ms[a]) / d);
  }
  t = std::max(t, 0.0);
  return {ms[0] + t * (xs[0] - ms[0]), ms[1] + t * (xs[1] - ms[1]), ms[2] + t * (xs[2] - ms[2])};
}

void symmetric_eigen(const Mat3d& m, Vec3d& values, Mat3d& vectors) {
  // The symmetric matrix as its diagonal d and its off-diagonal o[0] = (0,1), o[1] = (0,2),
  // o[2] = (1,2); a rotation in the (p, q) plane changes only d[p], d[q], o(p,q) (zeroed) and the
  // two entries coupling p and q to the third index r (Golub and Van Loan, Algorithm 8.4.1 with
  // the symmetric update: a few flops instead of two full 3x3 products).
  double d[3] = {m[0], m[4], m[8]};
  double o[3] = {m[1], m[2], m[5]};
  double v[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const double scale = std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]) + std::abs(o[0]) +
                       std::abs(o[1]) + std::abs(o[2]);
  // (p, q, r, index of o(p,q), of o(p,r), of o(q,r)) for the three planes, in cyclic order.
  static constexpr int kPlane[3][6] = {{0, 1, 2, 0, 1, 2}, {0, 2, 1, 1, 0, 2}, {1, 2, 0, 2, 0, 1}};
  for (int sweep = 0; sweep < 32; ++sweep) {
    const double off = std::abs(o[0]) + std::abs(o[1]) + std::abs(o[2]);
    if (off <= 1e-15 * scale || off == 0) break;
    for (const auto& pl : kPlane) {
      const int p = pl[0], q = pl[1], r = pl[2];
      double& apq = o[pl[3]];
      if (apq == 0) continue;
      // The rotation's tangent t = sign(h) g / (|h| + sqrt(h^2 + g^2)), h = d[q] - d[p],
      // g = 2 o(p,q) (Golub and Van Loan's theta = h / g multiplied out), and its cosine and sine
      // from the same denominator: one division per rotation instead of three.
      const double h = d[q] - d[p], g = 2 * apq;
      const double den = std::abs(h) + std::sqrt(h * h + g * g);
      const double sg = h >= 0 ? g : -g;
      const double inv = 1 / std::sqrt(den * den + g * g);
      const double c = den * inv, s = sg * inv, t = sg / den;
      d[p] -= t * apq;
      d[q] += t * apq;
      apq = 0;
      double& apr = o[pl[4]];
      double& aqr = o[pl[5]];
      const double pr = apr, qr = aqr;
      apr = c * pr - s * qr;
      aqr = s * pr + c * qr;
      for (int k = 0; k < 3; ++k) {  // V <- V G
        const double vkp = v[k][p], vkq = v[k][q];
        v[k][p] = c * vkp - s * vkq;
        v[k][q] = s * vkp + c * vkq;
      }
      (void)r;
    }
  }
  values = {d[0], d[1], d[2]};
  vectors = {v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1], v[2][2]};
}

QefSolution solve_qef(const Qef& qef, double eps) {
  QefSolution out;
  if (qef.count == 0) return out;
  const Vec3d mass = qef.mass_point();
  // Solve A^T A y = A^T b - A^T A m for the offset y from the mass point.
  const Mat3d ata = full(qef.ata);
  const Vec3d rhs = qef.atb - ata * mass;
  Vec3d lambda;
  Mat3d v;
  symmetric_eigen(ata, lambda, v);
  const double sigma_max = std::sqrt(std::max({lambda.x, lambda.y, lambda.z, 0.0}));
  double lam[3] = {lambda.x, lambda.y, lambda.z};
  Vec3d y{};
  // Singular values within a relative kCutoffTolerance of the cut-off are kept. A 0/1 field's
  // symmetric cells put some exactly on it (square pixels, the default eps of one half), and which
  // side rounding puts them on differs between a cell and its mirror image, whose vertex would
  // then differ by up to a third of a voxel instead of mirroring it (Dual Contouring solves a
  // neighbourhood's mirror images once, dual_contouring.cpp).
  constexpr double kCutoffTolerance = 1e-9;
  for (int i = 0; i < 3; ++i) {
    const double sigma = std::sqrt(std::max(lam[i], 0.0));
    if (sigma_max <= 0 || sigma < eps * sigma_max * (1 - kCutoffTolerance)) continue;
    const Vec3d axis{v[i], v[3 + i], v[6 + i]};
    y = y + (dot(axis, rhs) / lam[i]) * axis;
    ++out.rank;
  }
  out.position = mass + y;
  out.error = qef.error(out.position);
  return out;
}

}  // namespace segmesh
