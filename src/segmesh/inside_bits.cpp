#include "segmesh/inside_bits.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "segmesh/row_trim.hpp"

namespace segmesh {

namespace {

InsideBits empty_bits(const std::array<int64_t, 3>& dims) {
  InsideBits b;
  b.dims = dims;
  b.words = (dims[0] + 63) / 64 + 1;
  b.bits.assign(static_cast<size_t>(b.words * dims[1] * dims[2]), 0);
  return b;
}

}  // namespace

template <class T>
InsideBits inside_bits(const Volume<T>& field, double iso, Progress& progress) {
  InsideBits b = empty_bits(field.grid.dims);
  const InsideTest<T> inside(iso);
  const int64_t nx = b.dims[0], rows = b.dims[1] * b.dims[2];
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows, 256), [&](const auto& range) {
    throw_if_cancelled(progress);
    for (int64_t r = range.begin(); r < range.end(); ++r) {
      const T* v = field.voxels.data() + static_cast<size_t>(r * nx);
      uint64_t* out = b.bits.data() + static_cast<size_t>(r * b.words);
      for (int64_t w = 0; w * 64 < nx; ++w) {
        const int64_t end = std::min<int64_t>(64, nx - 64 * w);
        const T* p = v + 64 * w;
        uint64_t word = 0;
        for (int64_t x = 0; x < end; ++x) word |= uint64_t{inside(p[x])} << x;
        out[w] = word;
      }
    }
  });
  return b;
}

InsideBits inside_bits(const Components& components, const Component& component, FieldMargin margin) {
  const std::array<int64_t, 3> dims{component.last[0] - component.first[0] + 1 + 2 * margin[0],
                                    component.last[1] - component.first[1] + 1 + 2 * margin[1],
                                    component.last[2] - component.first[2] + 1 + 2 * margin[2]};
  InsideBits b = empty_bits(dims);
  const int64_t x0 = component.first[0] - margin[0], y0 = component.first[1] - margin[1],
                z0 = component.first[2] - margin[2];
  for (const VoxelRun& run : components.runs_of(component)) {
    uint64_t* row = b.bits.data() + static_cast<size_t>(((run.z - z0) * dims[1] + (run.y - y0)) * b.words);
    const int64_t lo = run.x_begin - x0, hi = run.x_end - x0;  // [lo, hi), hi > lo
    const int64_t wl = lo >> 6, wh = (hi - 1) >> 6;
    const uint64_t first = ~uint64_t{0} << (lo & 63);
    const uint64_t last = ~uint64_t{0} >> (63 - ((hi - 1) & 63));
    if (wl == wh) {
      row[wl] |= first & last;
      continue;
    }
    row[wl] |= first;
    for (int64_t w = wl + 1; w < wh; ++w) row[w] = ~uint64_t{0};
    row[wh] |= last;
  }
  return b;
}

template InsideBits inside_bits(const Volume<uint8_t>&, double, Progress&);
template InsideBits inside_bits(const Volume<int32_t>&, double, Progress&);
template InsideBits inside_bits(const Volume<float>&, double, Progress&);

}  // namespace segmesh
