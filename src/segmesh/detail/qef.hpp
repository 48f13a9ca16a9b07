// The quadratic error function of Dual Contouring (Ju, Losasso, Schaefer and Warren 2002):
// E(x) = sum_i (n_i . (x - p_i))^2 over the Hermite data (intersection points p_i with unit
// normals n_i) of a cell, minimised where the tangent planes meet — at a corner or on an edge of
// the shape where the planes say so, which is how Dual Contouring keeps sharp features.
//
// The normal equations (A^T A, A^T b, b^T b) are accumulated relative to the mass point (the mean
// of the p_i) and solved through the eigen-decomposition of the symmetric 3x3 A^T A by cyclic
// Jacobi (Givens) rotations. Directions whose singular value is below eps times the largest are
// dropped (a truncated pseudo-inverse): on a flat patch the solution then stays at the mass point
// instead of sliding along the plane. Cost: a few dozen flops per sample, one 3x3 solve.
#pragma once

#include <array>
#include <cstdint>

#include "segmesh/vec3.hpp"

namespace segmesh {

struct Qef {
  std::array<double, 6> ata{};  // xx, xy, xz, yy, yz, zz of A^T A
  Vec3d atb{};                  // A^T b
  double btb = 0;               // b^T b
  Vec3d point_sum{};            // sum of the p_i (mass point = point_sum / count)
  int count = 0;

  void add(Vec3d p, Vec3d n);
  void merge(const Qef& other);
  Vec3d mass_point() const { return count ? (1.0 / count) * point_sum : Vec3d{}; }
  // The same samples expressed in a frame whose origin lies at -offset (every p_i + offset), so
  // QEFs accumulated in different local frames can be merged.
  Qef translated(Vec3d offset) const;
  double error(Vec3d x) const;  // E(x)
};

struct QefSolution {
  Vec3d position;
  double error = 0;  // E at position
  int rank = 0;      // singular values kept
};

// Minimises E, dropping singular values below eps * the largest (those within a relative 1e-9
// of that cut-off are kept, so that rounding never decides).
QefSolution solve_qef(const Qef& qef, double eps);

// Moves x back along the line towards the mass point (itself first clamped into the box) until it
// lies in the box [lo, hi]: how a QEF vertex is kept inside its cell.
Vec3d keep_in_box(Vec3d x, Vec3d mass, Vec3d lo, Vec3d hi);

// Eigen-decomposition of a symmetric 3x3 matrix (row-major) by cyclic Jacobi rotations:
// eigenvalues in `values`, eigenvectors as the columns of `vectors` (row-major).
void symmetric_eigen(const Mat3d& m, Vec3d& values, Mat3d& vectors);

}  // namespace segmesh
