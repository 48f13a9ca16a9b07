#include "segmesh/detail/material_faces.hpp"

namespace segmesh {

Vec3d cell_point(int p) {
  if (p < 12) {
    const auto& a = kMcCornerOffset[kMcEdgeCorner[p][0]];
    const auto& b = kMcCornerOffset[kMcEdgeCorner[p][1]];
    return {0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
  }
  if (p < kCentre) {
    const int f = p - kFacePoint, axis = f / 2, side = f % 2;
    Vec3d c{0.5, 0.5, 0.5};
    (axis == 0 ? c.x : axis == 1 ? c.y : c.z) = side;
    return c;
  }
  return {0.5, 0.5, 0.5};
}

int face_segments(const uint32_t* m, int f, bool joined_by_winner, FaceSegment* out) {
  const auto& c = kFaceCorners[f];
  const auto& e = kFaceEdges[f];
  const uint32_t q[4] = {m[c[0]], m[c[1]], m[c[2]], m[c[3]]};
  int n = 0;
  // Corner k cut off from the two corners next to it.
  auto cut_off = [&](int k) {
    out[n++] = {int8_t(e[(k + 3) % 4]), int8_t(e[k]), int8_t(c[k]), q[k], q[(k + 1) % 4]};
  };
  const bool diagonal02 = q[0] == q[2] && q[1] != q[0] && q[3] != q[0];
  const bool diagonal13 = q[1] == q[3] && q[0] != q[1] && q[2] != q[1];
  if (diagonal02 && diagonal13) {  // two materials on the diagonals: the binary rule
    const uint32_t w = winning_material(q[0], q[1]);
    const uint32_t joined = joined_by_winner ? w : (w == q[0] ? q[1] : q[0]);
    for (int k = 0; k < 4; ++k)
      if (q[k] != joined) cut_off(k);
    return n;
  }
  if (diagonal02) {  // the diagonal pair joins; the two others are cut off
    cut_off(1);
    cut_off(3);
    return n;
  }
  if (diagonal13) {
    cut_off(0);
    cut_off(2);
    return n;
  }
  int cut[4], cuts = 0;
  for (int k = 0; k < 4; ++k)
    if (q[k] != q[(k + 1) % 4]) cut[cuts++] = k;  // the edge from corner k to k + 1
  if (cuts == 2) {  // one segment between the two cut edges; corner cut[0] + 1 lies between them
    const int k = (cut[0] + 1) % 4;
    out[n++] = {int8_t(e[cut[0]]), int8_t(e[cut[1]]), int8_t(c[k]), q[k], q[cut[0]]};
    return n;
  }
  // Three or four materials around the face meet at its centre.
  for (int i = 0; i < cuts; ++i) {
    const int k = cut[i];
    out[n++] = {int8_t(kFacePoint + f), int8_t(e[k]), int8_t(c[k]), q[k], q[(k + 1) % 4]};
  }
  return n;
}

}  // namespace segmesh
