// Four floats in one SSE register, for the smoothing filters: a vertex's x, y, z and a fourth lane
// (the triangle count c_i where a buffer keeps it), with the few operations the filters need, and
// F4Buffer, a zeroed array of them whose pages every thread makes resident first.
//
// GCC's and Clang's vector extension: one SSE instruction per operation on x86-64, plain floats
// elsewhere. The filters' state and sums are small quantities (displacements, differences of
// neighbouring positions), which float holds to ~1e-7 of their size.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <stdexcept>

#include "segmesh/first_touch.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

typedef float F4 __attribute__((vector_size(16)));

inline F4 load3(const Vec3f& p) {
  return F4{p.x, p.y, p.z, 0.0f};
}
inline F4 with_w(F4 a, float w) {
  return F4{a[0], a[1], a[2], w};
}
inline Vec3d xyz_d(F4 a) {
  return {a[0], a[1], a[2]};
}
// (a.y, a.z, a.x, a.w), for the cross product in three shuffles.
inline F4 yzx(F4 a) {
  return __builtin_shufflevector(a, a, 1, 2, 0, 3);
}
inline F4 cross3(F4 a, F4 b) {
  return yzx(a * yzx(b) - yzx(a) * b);
}
// 1 / (2 c) for a vertex with c triangles: a sum over its triangles' other two corners counts
// each neighbour twice on a closed mesh. 0 for a vertex without triangles.
inline float half_inverse(float c) {
  return c > 0 ? 0.5f / c : 0.0f;
}

// n F4, zero. From calloc, which takes large blocks as fresh pages from the kernel, already zero
// (and clears smaller ones); their pages are made resident by every thread first (first_touch.hpp,
// which leaves zero pages zero). glibc's malloc aligns to 16 bytes on 64-bit systems, as F4 needs.
class F4Buffer {
 public:
  explicit F4Buffer(size_t n)
      : p_(static_cast<F4*>(std::calloc(std::max<size_t>(n, 1), sizeof(F4)))) {
    if (!p_) throw std::bad_alloc();
    if (reinterpret_cast<uintptr_t>(p_.get()) % alignof(F4) != 0)
      throw std::logic_error("smoothing: calloc returned memory aligned below 16 bytes");
    first_touch(p_.get(), n * sizeof(F4));
  }
  F4* data() const { return p_.get(); }

 private:
  struct Free {
    void operator()(F4* p) const { std::free(p); }
  };
  std::unique_ptr<F4, Free> p_;
};

}  // namespace segmesh
