#include "segmesh/detail/dc_vertices.hpp"

#include <algorithm>

#include "segmesh/detail/dc_neighbourhood_keys.hpp"

namespace segmesh::dc {

namespace {

// Keeps a QEF solution x inside its cell grown by `reach` of the cell on each side. On a 0/1 field
// (reach -kDcCellMargin) the cell is shrunk, so that vertices of neighbouring cells never
// coincide (which would make zero-area triangles). With several sheets in the cell, each stays in
// the cell shrunk by kDcCellMargin and in the box of its own crossings as far as that box reaches
// into it.
Vec3d keep_in_cell(const Grid& grid, Vec3d x, Vec3d m, Vec3d sheet_lo, Vec3d sheet_hi,
                   bool several, double reach) {
  const auto& s = grid.spacing;
  double lo[3], hi[3];
  const double slo[3] = {sheet_lo.x, sheet_lo.y, sheet_lo.z},
               shi[3] = {sheet_hi.x, sheet_hi.y, sheet_hi.z};
  const double r = several ? -kDcCellMargin : reach;
  for (int a = 0; a < 3; ++a) {
    lo[a] = -r * s[a];
    hi[a] = (1 + r) * s[a];
    if (several) {
      const double l = std::max(lo[a], slo[a]), h = std::min(hi[a], shi[a]);
      if (l <= h) lo[a] = l, hi[a] = h;
    }
  }
  return keep_in_box(x, m, {lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
}

}  // namespace

CellHermite key_hermite(const SheetSolve& s, uint64_t key, int cs) {
  Vec3d gradient[8];
  for (int n = 0; n < 8; ++n) {
    const int x = 1 + (n & 1), y = 1 + (n >> 1 & 1), z = 1 + (n >> 2);
    auto at = [&](int di, int dj, int dk) {
      return double(key_point(key, x + di, y + dj, z + dk));
    };
    gradient[n] = s.options.normals == NormalMethod::sobel ? sobel_gradient_of(at)
                                                           : central_gradient_of(at);
  }
  CellHermite h;
  for (int e = 0; e < 12; ++e) {
    const int c0 = kMcEdgeCorner[e][0], c1 = kMcEdgeCorner[e][1];
    if ((cs >> c0 & 1) == (cs >> c1 & 1)) continue;
    const int axis = e / 4;
    EdgeCrossing c;  // as edge_crossing: t = 0.5 between a 0 and a 1
    c.t = 0.5;
    c.index_point = {1 + (c0 & 1) + c.t * (axis == 0), 1 + (c0 >> 1 & 1) + c.t * (axis == 1),
                     1 + (c0 >> 2) + c.t * (axis == 2)};
    c.index_gradient = (1 - c.t) * gradient[c0] + c.t * gradient[c1];
    store_crossing(s, h, e, cs, c, 1, 1, 1);
  }
  return h;
}

CellVertices solve_sheets(const SheetSolve& s, const CellHermite& h, int cs, Qef* qefs) {
  const auto& sp = s.grid.spacing;
  const DcCase& dc = s.table.cases[static_cast<size_t>(cs)];
  CellVertices out;
  for (int piece = 0; piece < dc.piece_count; ++piece) {
    Qef qef;
    Vec3d normal_sum{};
    Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    for (int t = 0; t < dc.piece_edge_count[piece]; ++t) {
      const int e = dc.piece_edges[piece][t];
      const Vec3d p = h.point[e], n = h.normal[e];
      qef.add(p, n);
      normal_sum = normal_sum + n;
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    // A cell crossed by several sheets is a configuration of single voxels touching at an edge
    // or corner, where tangent planes say nothing about a feature and the sheets' QEF minima
    // may coincide (the three quads of the tube all meet at the cell centre): each sheet takes
    // its mass point, which keeps the sheets apart.
    const Vec3d target =
        dc.piece_count > 1 ? qef.mass_point() : solve_qef(qef, s.options.svd_eps).position;
    const Vec3d p =
        keep_in_cell(s.grid, target, qef.mass_point(), lo, hi, dc.piece_count > 1, s.reach);
    out.offset[piece] = {p.x / sp[0], p.y / sp[1], p.z / sp[2]};
    out.normal_sum[piece] = normal_sum;
    if (qefs) qefs[piece] = qef;
  }
  return out;
}

Vec3f world_normal(const Grid& grid, Vec3d normal_sum) {
  const Vec3d wn = grid.direction * normal_sum;
  const double wl = norm(wn);
  return wl > 0 ? to_float((1.0 / wl) * wn) : Vec3f{0, 0, 1};
}

}  // namespace segmesh::dc
