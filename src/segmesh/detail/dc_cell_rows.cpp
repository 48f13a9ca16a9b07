#include "segmesh/detail/dc_cell_rows.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "segmesh/first_touch.hpp"

namespace segmesh::dc {

CellRows::CellRows(const InsideBits& b, const DcTable& t)
    : bits(b),
      table(t),
      nx(b.dims[0]),
      ny(b.dims[1]),
      nz(b.dims[2]),
      cx(nx - 1),
      cy(ny - 1),
      cz(nz - 1),
      cw((cx + 63) / 64) {
  for (int cs = 0; cs < 256; ++cs) {
    const DcCase& dc = table.cases[static_cast<size_t>(cs)];
    bool r = dc.piece_count != 1;
    for (int e = 0; e < 12; ++e) r = r || dc.around_count[e] > 1;
    rare[static_cast<size_t>(cs)] = r;
    if (r && cs != 0 && cs != 255 && (CornerWords::of_case(cs).maybe_rare() & 1) == 0) {
      throw std::logic_error("dual contouring: a rare case the word test misses");
    }
  }
}

namespace {

// Pass 1 for row (j, k).
void count_row(CellRows& c, int64_t j, int64_t k) {
  CellWord* out = c.words.data() + c.row_index(j, k) * size_t(c.cw);
  uint32_t* first = c.word_first.get() + c.row_index(j, k) * size_t(c.cw);
  const CornerRows rows = c.corners(j, k);
  uint64_t rare_any = 0, sheets = 0, triangles = 0;
  bool short_row = j + 1 >= c.cy || k + 1 >= c.cz;
  for (int64_t w = 0; w < c.cw; ++w) {
    const CornerWords cw = rows.at(w);
    CellWord word{cw.nontrivial() & c.valid(w), 0};
    if (word.cells == 0) continue;  // most words (words starts zeroed): no rare test
    first[w] = static_cast<uint32_t>(sheets);
    sheets += uint64_t(std::popcount(word.cells));
    const uint64_t e7 = cw.cut7() & word.cells, e11 = cw.cut11() & word.cells;
    triangles += 2 * uint64_t(std::popcount(cw.cut3() & word.cells) + std::popcount(e7) +
                              std::popcount(e11));
    // Edges 7 and 11 of the row's last cell need cells past the row's end.
    if (w == c.cw - 1 && (e7 | e11) >> ((c.cx - 1) & 63) & 1) short_row = true;
    for (uint64_t m = word.cells & cw.maybe_rare(); m != 0; m &= m - 1) {
      const int b = std::countr_zero(m);
      const int cs = cw.case_of(b);
      if (c.rare[static_cast<size_t>(cs)]) {
        word.rare |= uint64_t{1} << b;
        sheets += uint64_t(c.pieces(cs)) - 1;
      }
    }
    rare_any |= word.rare;
    out[w] = word;
  }
  c.vertex_first[c.row_index(j, k) + 1] = count32(sheets);
  c.triangle_first[c.row_index(j, k) + 1] = count32(triangles);
  c.row_rare[c.row_index(j, k)] = rare_any != 0;
  c.row_short[c.row_index(j, k)] = short_row && triangles > 0;
}

}  // namespace

void count_cells(CellRows& c, Progress& progress) {
  const size_t n = static_cast<size_t>(c.rows());
  resize_zeroed(c.words, n * size_t(c.cw));
  c.word_first.reset(new uint32_t[n * size_t(c.cw)]);  // set where cells are
  c.row_rare.assign(n, 0);
  c.row_short.assign(n, 0);
  c.vertex_first.assign(n + 1, 0);
  c.triangle_first.assign(n + 1, 0);
  c.extra_first.assign(n + 1, 0);
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, c.rows(), 64), [&](const auto& range) {
    throw_if_cancelled(progress);
    for (int64_t r = range.begin(); r < range.end(); ++r) count_row(c, r % c.cy, r / c.cy);
  });
}

void prefix_sums(CellRows& c) {
  uint64_t sheets = 0, triangles = 0, extra = 0;
  for (size_t r = 0; r < static_cast<size_t>(c.rows()); ++r) {
    sheets += c.vertex_first[r + 1];
    triangles += c.triangle_first[r + 1];
    extra += c.extra_first[r + 1];
    mesh_id_count(sheets + extra, "dual contouring");
    c.vertex_first[r + 1] = static_cast<uint32_t>(sheets);
    c.triangle_first[r + 1] = count32(triangles);
    c.extra_first[r + 1] = static_cast<uint32_t>(extra);
  }
}

std::vector<SurfaceCell> surface_cells(const CellRows& c) {
  std::vector<SurfaceCell> out;
  for (int64_t r = 0; r < c.rows(); ++r) {
    const int64_t j = r % c.cy, k = r / c.cy;
    uint32_t id = c.vertex_first[size_t(r)];
    const CellWord* row = c.row_words(j, k);
    for (int64_t w = 0; w < c.cw; ++w) {
      for (uint64_t m = row[w].cells; m != 0; m &= m - 1) {
        const int64_t x = 64 * w + std::countr_zero(m);
        const int cs = c.case_at(x, j, k);
        if (c.pieces(cs) > 0) out.push_back({int32_t(x), int32_t(j), int32_t(k), uint8_t(cs), id});
        id += static_cast<uint32_t>(c.pieces(cs));
      }
    }
  }
  return out;
}

}  // namespace segmesh::dc
