#include "segmesh/detail/volume_restoration.hpp"

#include <cmath>

namespace segmesh {

Restoration restore_volume(const Triangles& t, const std::vector<uint32_t>& idx, const Vec3f* o,
                           Vec3d centre, const F4* smoothed, size_t nv, F4* normal) {
  const auto original = [&](size_t i) { return to_d(o[i]) - centre; };
  const size_t nt = idx.size() / 3;
  // One pass for the normals, one over the triangles for both volumes and the cubic (the
  // normals are wasted only in the rare cases that return early).
  add_area_vectors(
      t, [&](uint32_t i) { return smoothed[i]; }, normal);
  for_each_vertex(nv, [&](size_t i) { normal[i] = unit_or(normal[i], F4{}); });
  const VolumeCubic k = block_sum<VolumeCubic>(nt, [&](size_t t0, size_t t1) {
    VolumeCubic s;
    for (size_t t = t0; t < t1; ++t) {
      const uint32_t* x = &idx[3 * t];
      add_triangle_cubic(s, original(x[0]), original(x[1]), original(x[2]), xyz_d(smoothed[x[0]]),
                         xyz_d(smoothed[x[1]]), xyz_d(smoothed[x[2]]), xyz_d(normal[x[0]]),
                         xyz_d(normal[x[1]]), xyz_d(normal[x[2]]));
    }
    return s;
  });
  return solve_restoration(k);
}

Restoration solve_restoration(const VolumeCubic& k) {
  const double target = k.original, volume = k.k0;  // both times 6
  if (!(target > 0)) return {};  // not a closed outward-wound surface: nothing to restore
  if (volume < 0.25 * target) return {.keep_original = true};
  if (std::abs(volume - target) <= 1e-9 * target) return {};
  double delta = 0;  // no step if the derivative k1 is not positive
  for (int step = 0; step < 50; ++step) {
    const double g = k.at(delta) - target;
    const double dg = k.k1 + delta * (2 * k.k2 + delta * 3 * k.k3);
    if (!(dg > 0)) break;
    const double change = g / dg;
    if (!std::isfinite(change)) break;
    delta -= change;
    if (std::abs(change) <= 1e-15 * std::abs(delta)) break;
  }
  return {.delta = std::isfinite(delta) ? delta : 0.0};
}

}  // namespace segmesh
