// Analytic shapes with sharp features and a smooth one, as exact signed distance fields (inside
// positive), and how far a mesh stays from their true edges: what the Dual Contouring tests and
// bench/dc_sharp_edges.cpp measure sharp features and accuracy with.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "segmesh/grid.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh::test {

inline Mat3d rotation(double ax, double ay, double az) {
  const Mat3d rx{1, 0, 0, 0, std::cos(ax), -std::sin(ax), 0, std::sin(ax), std::cos(ax)};
  const Mat3d ry{std::cos(ay), 0, std::sin(ay), 0, 1, 0, -std::sin(ay), 0, std::cos(ay)};
  const Mat3d rz{std::cos(az), -std::sin(az), 0, std::sin(az), std::cos(az), 0, 0, 0, 1};
  auto mul = [](const Mat3d& a, const Mat3d& b) {
    Mat3d c{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) c[3 * i + j] += a[3 * i + k] * b[3 * k + j];
    return c;
  };
  return mul(rz, mul(ry, rx));
}

inline Mat3d transpose(const Mat3d& m) {
  return {m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]};
}

inline double percentile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * double(v.size() - 1))];
}

// A cube of half-side h centred at the origin, turned by `rotation`.
struct RotatedCube {
  Mat3d rotation;
  double h;

  // Exact signed distance, inside positive.
  double operator()(Vec3d p) const {
    const Vec3d q = transpose(rotation) * p;
    const Vec3d d{std::abs(q.x) - h, std::abs(q.y) - h, std::abs(q.z) - h};
    const Vec3d out{std::max(d.x, 0.0), std::max(d.y, 0.0), std::max(d.z, 0.0)};
    return -(norm(out) + std::min(std::max({d.x, d.y, d.z}), 0.0));
  }

  // Points along the twelve edges, `per_edge` - 1 on each, corners excluded.
  std::vector<Vec3d> edge_points(int per_edge = 40) const {
    std::vector<Vec3d> points;
    for (int axis = 0; axis < 3; ++axis)
      for (int a = -1; a <= 1; a += 2)
        for (int b = -1; b <= 1; b += 2)
          for (int s = 1; s < per_edge; ++s) {
            double p[3];
            p[axis] = h * (-1 + 2.0 * s / per_edge);
            p[(axis + 1) % 3] = a * h;
            p[(axis + 2) % 3] = b * h;
            points.push_back(rotation * Vec3d{p[0], p[1], p[2]});
          }
    return points;
  }

  double volume() const { return 8 * h * h * h; }
};

// The 90th percentile of the distances from `points` to `mesh`.
inline double p90_distance(const TriMesh& mesh, const std::vector<Vec3d>& points) {
  const MeshDistance to(mesh);
  std::vector<double> d;
  d.reserve(points.size());
  for (const Vec3d& p : points) d.push_back(to.distance(p));
  return percentile(std::move(d), 0.9);
}

// An isotropic grid of `voxel` mm centred on the world origin, reaching `extent` mm each way.
inline Grid centred_grid(double extent, double voxel, Mat3d direction = identity3()) {
  Grid g;
  g.spacing = {voxel, voxel, voxel};
  g.direction = direction;
  for (int a = 0; a < 3; ++a) g.dims[a] = static_cast<int64_t>(2 * extent / voxel) + 1;
  const Vec3d half = g.to_world({double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2,
                                 double(g.dims[2] - 1) / 2});
  g.origin = {-half.x, -half.y, -half.z};
  return g;
}

}  // namespace segmesh::test
