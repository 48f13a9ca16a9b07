#include "segmesh/detail/smoothing_sweeps.hpp"

#include <algorithm>
#include <limits>

namespace segmesh {

void write_normals(TriMesh& mesh, const Triangles& t, F4* scratch) {
  const Vec3f* p = mesh.positions.data();
  add_area_vectors(
      t, [&](uint32_t i) { return load3(p[i]); }, scratch);
  resize_zeroed(mesh.normals, mesh.positions.size());
  for_each_vertex(mesh.positions.size(), [&](size_t i) {
    const F4 n = unit_or(scratch[i], F4{0, 0, 1, 0});
    mesh.normals[i] = {n[0], n[1], n[2]};
  });
}

// Each block reads its positions as a flat run of floats, twelve lanes at a time (four positions:
// lane k holds coordinate k mod 3), with comparisons and selects that compilers vectorise
// (std::min on floats they do not).
Vec3d box_centre(const std::vector<Vec3f>& p) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  struct Box {
    Vec3f lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
    Box operator+(const Box& o) const {
      return {{std::min(lo.x, o.lo.x), std::min(lo.y, o.lo.y), std::min(lo.z, o.lo.z)},
              {std::max(hi.x, o.hi.x), std::max(hi.y, o.hi.y), std::max(hi.z, o.hi.z)}};
    }
  };
  static_assert(sizeof(Vec3f) == 3 * sizeof(float));
  const Box box = block_sum<Box>(p.size(), [&](size_t i0, size_t i1) {
    constexpr size_t kLanes = 12;
    float lo[kLanes], hi[kLanes];
    std::fill(lo, lo + kLanes, kInf);
    std::fill(hi, hi + kLanes, -kInf);
    const float* f = &p[i0].x;
    const size_t n = 3 * (i1 - i0);
    size_t k = 0;
    for (; k + kLanes <= n; k += kLanes) {
      for (size_t l = 0; l < kLanes; ++l) {
        const float v = f[k + l];
        lo[l] = v < lo[l] ? v : lo[l];
        hi[l] = v > hi[l] ? v : hi[l];
      }
    }
    for (size_t l = 0; k + l < n; ++l) {  // the last positions, fewer than four
      lo[l] = std::min(lo[l], f[k + l]);
      hi[l] = std::max(hi[l], f[k + l]);
    }
    Box b;
    for (size_t l = 0; l < kLanes; l += 3)
      b = b + Box{{lo[l], lo[l + 1], lo[l + 2]}, {hi[l], hi[l + 1], hi[l + 2]}};
    return b;
  });
  return 0.5 * (to_d(box.lo) + to_d(box.hi));
}

}  // namespace segmesh
