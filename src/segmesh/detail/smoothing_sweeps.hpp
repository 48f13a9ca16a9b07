// The passes the smoothing filters are made of: over the vertices in parallel, over the triangles
// as scatters into their corners (triangle_scatter.hpp), and sums over fixed blocks, so that every
// result is the same for any thread count. Also the pieces shared by the filters, the volume
// restoration and the vertex normals: area vectors, unit normals, the bounding-box centre, and
// the per-iteration progress and cancellation check.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "segmesh/detail/float4.hpp"
#include "segmesh/detail/triangle_scatter.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

// Vertices per task: enough work to amortise scheduling, small enough to balance two to a few
// dozen cores. Triangles per block of the volume sums: the blocks, not the threads, fix the order
// in which floating-point partial sums are added. Results never depend on the thread count.
constexpr size_t kVertexGrain = 4096;
constexpr size_t kTriangleBlock = 8192;

template <class F>
void for_each_vertex(size_t n, F&& body) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kVertexGrain),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) body(i);
                    });
}

// f(first, last) over fixed blocks of [0, n), the partial results added in block order.
template <class T, class F>
T block_sum(size_t n, F&& f) {
  const size_t blocks = (n + kTriangleBlock - 1) / kTriangleBlock;
  std::vector<T> partial(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    partial[b] = f(b * kTriangleBlock, std::min(n, (b + 1) * kTriangleBlock));
  });
  T total{};
  for (const T& p : partial) total = total + p;
  return total;
}

inline Vec3d to_d(const Vec3f& v) {
  return {v.x, v.y, v.z};
}

// Cancellation check before and progress report after each iteration.
class Ticker {
 public:
  Ticker(Progress& progress, int total) : progress_(progress), total_(total) {}
  void begin() const { throw_if_cancelled(progress_); }
  void end() { progress_.update(double(++done_) / double(total_)); }

 private:
  Progress& progress_;
  int total_, done_ = 0;
};

// The triangles of a mesh as the sweeps visit them (triangle_scatter.hpp). Triangles with a
// repeated corner add nothing to the umbrella sums (they have no area and their edges are the
// other triangles').
struct Triangles {
  const uint32_t* idx;
  TriangleChunks chunks;

  // f(t, a, b, c) for every triangle t = (a, b, c).
  template <class F>
  void each_indexed(F&& f) const {
    scatter_triangles(chunks, [&](size_t t0, size_t t1) {
      for_each_interleaved(
          t0, t1, [&](size_t t) { f(t, idx[3 * t], idx[3 * t + 1], idx[3 * t + 2]); });
    });
  }
  template <class F>
  void each(F&& f) const {
    each_indexed([&](size_t, uint32_t a, uint32_t b, uint32_t c) { f(a, b, c); });
  }
  template <class F>
  void each_proper(F&& f) const {
    each([&](uint32_t a, uint32_t b, uint32_t c) {
      if (a != b && b != c && c != a) f(a, b, c);
    });
  }
  // each_proper, then finish(v0, v1) over the vertices as they become complete
  // (scatter_then_finish; plan = finish_plan(chunks, vertex count)).
  template <class F, class Finish>
  void each_proper_then(const FinishPlan& plan, F&& f, Finish&& finish) const {
    scatter_then_finish(
        chunks, plan,
        [&](size_t t0, size_t t1) {
          for_each_interleaved(t0, t1, [&](size_t t) {
            __builtin_prefetch(idx + 3 * (t + 32));
            const uint32_t a = idx[3 * t], b = idx[3 * t + 1], c = idx[3 * t + 2];
            if (a != b && b != c && c != a) f(a, b, c);
          });
        },
        finish);
  }
};

// acc_i += (b - a) x (c - a) for each corner i of every triangle (a, b, c): twice the area
// vector of the triangles at i, for positions pos(j) (F4); turned around for the triangles t
// where turned(t) (a surface whose triangles are wound either way about their vertices).
template <class Pos, class Turned>
void add_area_vectors(const Triangles& t, Pos&& pos, F4* acc, Turned&& turned) {
  t.each_indexed([&](size_t i, uint32_t a, uint32_t b, uint32_t c) {
    const F4 pa = pos(a);
    F4 n = cross3(pos(b) - pa, pos(c) - pa);
    if (turned(i)) n = F4{} - n;
    acc[a] += n;
    acc[b] += n;
    acc[c] += n;
  });
}
template <class Pos>
void add_area_vectors(const Triangles& t, Pos&& pos, F4* acc) {
  add_area_vectors(t, pos, acc, [](size_t) { return false; });
}

// The unit vector of acc_i's x, y, z, or `otherwise` where that is zero (or not finite).
inline F4 unit_or(F4 v, F4 otherwise) {
  const float length = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return length > 0 && std::isfinite(length) ? with_w(v * (1.0f / length), 0.0f) : otherwise;
}

// mesh.normals from the area vectors of mesh.positions (scratch: zero, nv entries).
void write_normals(TriMesh& mesh, const Triangles& t, F4* scratch);

// The centre of the bounding box of the positions (exact: minima and maxima do not depend on the
// order of evaluation).
Vec3d box_centre(const std::vector<Vec3f>& p);

}  // namespace segmesh
