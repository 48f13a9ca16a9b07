#include "segmesh/detail/inside_bits.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "segmesh/first_touch.hpp"
#include "segmesh/detail/row_trim.hpp"

namespace segmesh {

namespace {

InsideBits empty_bits(const std::array<int64_t, 3>& dims) {
  InsideBits b;
  b.dims = dims;
  b.words = (dims[0] + 63) / 64 + 1;
  resize_zeroed(b.bits, static_cast<size_t>(b.words * dims[1] * dims[2]));
  return b;
}

}  // namespace

#if defined(__SSE2__)
namespace {

// column_bytes' interleave, in registers: v[m] holds byte m of rows[0 .. 15][w].
void interleave_bytes(const uint64_t* const* rows, int64_t w, __m128i v[8]) {
  // Bytes: A[n][m] is byte m of rows[n][w]. Interleave rows in pairs, fours, eights, sixteens.
  __m128i e[8], f[8], g[8];
  for (int t = 0; t < 8; ++t) {
    const __m128i pair = _mm_set_epi64x(static_cast<int64_t>(rows[2 * t + 1][w]),
                                        static_cast<int64_t>(rows[2 * t][w]));
    e[t] = _mm_unpacklo_epi8(pair, _mm_srli_si128(pair, 8));  // 16 bits m: rows 2t, 2t + 1
  }
  for (int u = 0; u < 4; ++u) {  // 32 bits m: rows 4u .. 4u + 3, m = 0 .. 3, then 4 .. 7
    f[2 * u] = _mm_unpacklo_epi16(e[2 * u], e[2 * u + 1]);
    f[2 * u + 1] = _mm_unpackhi_epi16(e[2 * u], e[2 * u + 1]);
  }
  for (int h = 0; h < 2; ++h) {  // 64 bits m: rows 8h .. 8h + 7; g[4h + q] holds m = 2q, 2q + 1
    for (int half = 0; half < 2; ++half) {
      const __m128i a = f[4 * h + half], b = f[4 * h + 2 + half];
      g[4 * h + 2 * half] = _mm_unpacklo_epi32(a, b);
      g[4 * h + 2 * half + 1] = _mm_unpackhi_epi32(a, b);
    }
  }
  for (int q = 0; q < 4; ++q) {
    v[2 * q] = _mm_unpacklo_epi64(g[q], g[4 + q]);
    v[2 * q + 1] = _mm_unpackhi_epi64(g[q], g[4 + q]);
  }
}

}  // namespace
#endif

void column_bytes(const uint64_t* const* rows, int64_t w, ColumnBytes& out) {
#if defined(__SSE2__)
  __m128i v[8];
  interleave_bytes(rows, w, v);
  for (int m = 0; m < 8; ++m) _mm_store_si128(reinterpret_cast<__m128i*>(out.lane[m]), v[m]);
#else
  for (int m = 0; m < 8; ++m) {
    for (int n = 0; n < 16; ++n) out.lane[m][n] = static_cast<uint8_t>(rows[n][w] >> (8 * m));
  }
#endif
}

void column_codes(const uint64_t* const* rows, int64_t w, uint16_t* codes) {
#if defined(__SSE2__)
  // Bit i of byte n of v[m] is the bit wanted for column 8 m + i.
  __m128i v[8];
  interleave_bytes(rows, w, v);
  for (int m = 0; m < 8; ++m) {
    // movemask takes bit 7 of each byte; a 16-bit shift moves bit i there in both bytes.
    codes[8 * m + 0] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 7)));
    codes[8 * m + 1] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 6)));
    codes[8 * m + 2] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 5)));
    codes[8 * m + 3] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 4)));
    codes[8 * m + 4] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 3)));
    codes[8 * m + 5] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 2)));
    codes[8 * m + 6] = static_cast<uint16_t>(_mm_movemask_epi8(_mm_slli_epi16(v[m], 1)));
    codes[8 * m + 7] = static_cast<uint16_t>(_mm_movemask_epi8(v[m]));
  }
#else
  for (int b = 0; b < 64; ++b) codes[b] = column_at(rows, 64 * w + b);
#endif
}

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

InsideBits inside_bits(const Components& components, const Component& component,
                       FieldMargin margin) {
  const std::array<int64_t, 3> dims{component.last[0] - component.first[0] + 1 + 2 * margin[0],
                                    component.last[1] - component.first[1] + 1 + 2 * margin[1],
                                    component.last[2] - component.first[2] + 1 + 2 * margin[2]};
  InsideBits b = empty_bits(dims);
  const int64_t x0 = component.first[0] - margin[0], y0 = component.first[1] - margin[1],
                z0 = component.first[2] - margin[2];
  for (const VoxelRun& run : components.runs_of(component)) {
    uint64_t* row =
        b.bits.data() + static_cast<size_t>(((run.z - z0) * dims[1] + (run.y - y0)) * b.words);
    set_bit_run(row, run.x_begin - x0, run.x_end - x0);
  }
  return b;
}

template InsideBits inside_bits(const Volume<uint8_t>&, double, Progress&);
template InsideBits inside_bits(const Volume<int32_t>&, double, Progress&);
template InsideBits inside_bits(const Volume<float>&, double, Progress&);

}  // namespace segmesh
