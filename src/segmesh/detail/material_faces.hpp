// The face rule of multi-label extraction: how the cut edges on one face of a cell are joined
// when the face's four corners hold up to four materials (multi_label_marching_cubes.hpp says the
// rule; multi_label_dual_contouring.hpp uses the same one, so both extractors' surfaces meet the
// cell faces alike). A decision depends on the face's four corners only, so the two cells sharing
// a face agree. Cost: a few comparisons per face.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

// Points of a cell: 0..11 the edges' midpoints, 12 + f the centre of face f, 18 the cell's centre.
inline constexpr int kFacePoint = 12;
inline constexpr int kCentre = 18;

// Face f = 2 * axis + side; its corners in cyclic order (side: the corners' bit `axis`).
inline constexpr std::array<std::array<int, 4>, 6> kFaceCorners = [] {
  std::array<std::array<int, 4>, 6> f{};
  for (int a = 0; a < 3; ++a) {
    const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
    const int uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int s = 0; s < 2; ++s)
      for (int q = 0; q < 4; ++q) f[2 * a + s][q] = s << a | uv[q][0] << u | uv[q][1] << v;
  }
  return f;
}();

constexpr int edge_of(int c0, int c1) {
  for (int e = 0; e < 12; ++e) {
    if ((kMcEdgeCorner[e][0] == c0 && kMcEdgeCorner[e][1] == c1) ||
        (kMcEdgeCorner[e][0] == c1 && kMcEdgeCorner[e][1] == c0))
      return e;
  }
  return -1;
}

// The cell edge between corners q and q + 1 of face f.
inline constexpr std::array<std::array<int, 4>, 6> kFaceEdges = [] {
  std::array<std::array<int, 4>, 6> e{};
  for (int f = 0; f < 6; ++f)
    for (int q = 0; q < 4; ++q) e[f][q] = edge_of(kFaceCorners[f][q], kFaceCorners[f][(q + 1) % 4]);
  return e;
}();

// Point p of a cell (above) in cell coordinates, 0..1 on each axis.
Vec3d cell_point(int p);

// Corner c of a cell in cell coordinates.
inline Vec3d cell_corner(int c) {
  const auto& o = kMcCornerOffset[c];
  return {double(o[0]), double(o[1]), double(o[2])};
}

// The material that wins a pair: any part over the background, the earlier part over a later one.
inline uint32_t winning_material(uint32_t a, uint32_t b) {
  if (a == 0) return b;
  if (b == 0) return a;
  return std::min(a, b);
}

// A segment of the surface on a cell face, between points p and q, with material `a` on the side
// of corner `corner` and `b` on the other.
struct FaceSegment {
  int8_t p = 0, q = 0, corner = 0;
  uint32_t a = 0, b = 0;
};

// The segments of face f as its corners' materials decide (the rule in
// multi_label_marching_cubes.hpp); joined_by_winner: the
// binary face rule (connectivity 18, 26) joins the winner's diagonal, else the other's.
int face_segments(const uint32_t* m, int f, bool joined_by_winner, FaceSegment* out);

}  // namespace segmesh
