// Triangle quality by the normalised radii ratio rho = 2 r / R (r the inradius, R the
// circumradius): 1 for an equilateral triangle, 0 for a degenerate one (collinear corners or a
// zero-length edge). It is the quality measure of ../shared/tools/mesh_metrics.py and of the
// comparison tables, so our numbers and the peer tools' numbers mean the same thing.
//
// Formula: rho = 8 (s-a)(s-b)(s-c) / (a b c), s the semi-perimeter (Pébay and Baker 2003,
// "Analysis of triangle quality measures", Math. Comp. 72). It is evaluated in double in Kahan's
// cancellation-free arrangement (W. Kahan, "Miscalculating area and angles of a needle-like
// triangle"): with the edges sorted a >= b >= c, 8 (s-a)(s-b)(s-c) = (c-(a-b)) (c+(a-b)) (a+(b-c)).
// The naive form loses every digit on needles (s-a is the difference of two nearly equal sums);
// this one keeps the relative error a few ulps of the edge lengths. A factor that rounding makes
// slightly negative is clamped to 0, the result is clamped to [0, 1].
//
// Guarantees: triangle_quality and vertex_quality are parallel (oneTBB) and give bit-identical
// results for any thread count: sums are taken over fixed blocks of triangles and the block sums
// combined in order; minima, counts and order statistics do not depend on order.
// Cost: O(triangles) time; O(triangles) extra memory for the 1st percentile (a selection, not a
// sort) and the per-triangle values of vertex_quality.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "segmesh/tri_mesh.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

// rho of the triangle (a, b, c), in [0, 1]; 0 when an edge has zero length or the corners are
// collinear.
double radii_ratio(Vec3d a, Vec3d b, Vec3d c);
// The same from the three side lengths (for callers that share sides between triangles).
double radii_ratio_of_sides(double a, double b, double c);

struct QualityStats {
  int64_t triangles = 0;
  double min = 0;  // worst rho
  double mean = 0;
  // 1st percentile, interpolated linearly between the order statistics around rank 0.01 (n-1)
  // (numpy's default, as mesh_metrics.py computes it); a robust minimum.
  double p01 = 0;
  // histogram[k] counts rho in [k/10, (k+1)/10); the last bin is closed, [0.9, 1.0].
  std::array<int64_t, 10> histogram{};
};

// Quality of every triangle of `mesh`. An empty mesh gives all zeros.
QualityStats triangle_quality(const TriMesh& mesh);

// Per vertex, the worst (smallest) rho of the triangles that use it; 1 for vertices no triangle
// uses. One value per entry of mesh.positions, ready for quality_colors.
std::vector<float> vertex_quality(const TriMesh& mesh);

// Linear ramp from pure blue (rho 0) to pure green (rho 1), alpha 255; rho is clamped to [0, 1]
// and NaN is shown as 0. One colour per value, e.g. for TriMesh::colors.
std::vector<Rgba8> quality_colors(const std::vector<float>& rho);

// The q-quantile (q in [0, 1]) of `values` with numpy's default linear interpolation: the order
// statistics at ranks floor(q (n-1)) and the next, mixed by the fractional part. Reorders
// `values` (a selection, O(n)); 0 for an empty vector. Shared with mesh_deviation's p95.
double percentile(std::vector<double>& values, double q);

}  // namespace segmesh
