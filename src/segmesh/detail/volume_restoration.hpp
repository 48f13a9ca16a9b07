// Volume restoration after smoothing: every vertex of a smoothed part moves along its unit normal
// by the one offset that gives the part back the volume it enclosed before smoothing, so smoothing
// does not shrink small parts (screws a few voxels across lose 1-8 % to every filter without it).
#pragma once

#include <cstdint>
#include <vector>

#include "segmesh/detail/float4.hpp"
#include "segmesh/detail/smoothing_sweeps.hpp"

namespace segmesh {

// Coefficients of 6 V(delta) = k0 + k1 delta + k2 delta^2 + k3 delta^3, the volume after every
// vertex moves by delta along its unit normal, and 6 times the original volume.
struct VolumeCubic {
  double k0 = 0, k1 = 0, k2 = 0, k3 = 0, original = 0;
  VolumeCubic operator+(const VolumeCubic& o) const {
    return {k0 + o.k0, k1 + o.k1, k2 + o.k2, k3 + o.k3, original + o.original};
  }
  // 6 V(delta).
  double at(double delta) const { return k0 + delta * (k1 + delta * (k2 + delta * k3)); }
};

struct Restoration {
  bool keep_original = false;
  double delta = 0;  // offset along the unit normals
};

// Triangle (a, b, c)'s terms of the cubic: original corners o0 o1 o2, smoothed a b c with unit
// normals na nb nc (all relative to one centre).
inline void add_triangle_cubic(VolumeCubic& s, Vec3d o0, Vec3d o1, Vec3d o2, Vec3d a, Vec3d b,
                               Vec3d c, Vec3d na, Vec3d nb, Vec3d nc) {
  s.original += dot(o0, cross(o1, o2));
  const Vec3d bc = cross(b, c), nbc = cross(nb, c), bnc = cross(b, nc), nbnc = cross(nb, nc);
  s.k0 += dot(a, bc);
  s.k1 += dot(na, bc) + dot(a, nbc) + dot(a, bnc);
  s.k2 += dot(na, nbc) + dot(na, bnc) + dot(a, nbnc);
  s.k3 += dot(na, nbnc);
}

// The offset that gives a closed surface with cubic k its original volume back (Newton's method
// from 0), or keep_original where it lost more than three quarters of it; nothing where it
// encloses no positive volume or already has its volume.
Restoration solve_restoration(const VolumeCubic& k);

// Gives the smoothed positions s(i) the enclosed volume V0 of the original ones o(i) (both
// relative to one centre, for well-conditioned sums): every vertex moves along its area-weighted
// unit normal (into `normal`) by the one offset delta that restores it. The volume after the move
// is a cubic in delta (VolumeCubic), solved by Newton's method from delta = 0 (whose first step
// is the first-order one, (V0 - V) / (dV/ddelta)). A part that smoothing nearly erased (below a
// quarter of its volume: specks of a few voxels) keeps its original positions instead; a mesh
// that encloses no positive volume is left as smoothed.
// `o` holds the original positions, `smoothed` the smoothed ones relative to `centre` (x, y, z);
// `normal` is zero and receives the unit normals of the smoothed positions.
Restoration restore_volume(const Triangles& t, const std::vector<uint32_t>& idx, const Vec3f* o,
                           Vec3d centre, const F4* smoothed, size_t nv, F4* normal);

}  // namespace segmesh
