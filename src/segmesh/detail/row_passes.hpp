// The row passes of the Marching Cubes extractors (marching_cubes.cpp: one part, from a field or
// from its runs; multi_label_marching_cubes.cpp: every part at once, from material rows), written
// once because both lay out their output the same way.
//
// The grid's rows of grid points (j, k), numbered r = k * ny + j, each own some vertices of a few
// kinds (their cut x-, y- and z-edges first, then whatever else the extractor places per row) and
// the triangles of the cells between them and the rows at y + 1, z + 1. Vertex ids follow the
// rows, and within a row the kinds in order; triangles follow the rows too. A counting pass sizes
// every row in parallel (count_rows), prefix sums give each row its first vertex id and first
// triangle, and a filling pass writes each row's disjoint output ranges in parallel (fill_rows):
// rows are independent, so the output is the same for any thread count.
//
// A cell finds the ids of its cut edges with one cursor per (row, axis) it touches
// (CutEdgeCursors), advanced as the cells of a row of cells are visited in x order: every cut edge
// of those rows is an edge of a visited cell, so no plane of edge ids is ever stored.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

// What one row contributes, added up in 64 bits by an extractor's counting.
template <size_t Kinds>
struct RowTally {
  std::array<uint64_t, Kinds> vertices{};  // per kind
  uint64_t triangles = 0;
};

// What one row contributes, stored: 32-bit, as the ids they count (mesh_id_count).
template <size_t Kinds>
struct RowCount {
  std::array<uint32_t, Kinds> vertices{};
  uint32_t triangles = 0;
};

// Every row's counts and first ids. Kinds 0, 1, 2 are the row's cut x-, y- and z-edges.
template <size_t Kinds>
struct RowIds {
  int64_t ny = 0;  // rows per slab
  std::vector<RowCount<Kinds>> counts;
  std::vector<uint32_t> vertex_first;    // first vertex id of each row; the vertex count last
  std::vector<uint32_t> triangle_first;  // first triangle of each row's cells; the count last
};

inline size_t row_of(int64_t ny, int64_t j, int64_t k) {
  return static_cast<size_t>(k * ny + j);
}

// The first id of row r's vertices of `kind`.
template <size_t Kinds>
uint32_t first_id(const RowIds<Kinds>& ids, size_t r, size_t kind) {
  uint32_t id = ids.vertex_first[r];
  for (size_t q = 0; q < kind; ++q) id += ids.counts[r].vertices[q];
  return id;
}

namespace row_passes_detail {
// Calls row(j, k, r) for every row of an ny x nz grid of rows in parallel, in blocks of rows,
// checking for cancellation before each block.
template <class Row, class AfterBlock>
void parallel_rows(int64_t ny, int64_t nz, Progress& progress, Row&& row,
                   AfterBlock&& after_block) {
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, ny * nz, 64), [&](const auto& range) {
    throw_if_cancelled(progress);
    for (int64_t r = range.begin(); r < range.end(); ++r)
      row(r % ny, r / ny, static_cast<size_t>(r));
    after_block(range.size());
  });
}
}  // namespace row_passes_detail

// The counting pass and the prefix sums: tally(j, k) -> RowTally<Kinds> for every row, in
// parallel. Throws segmesh::Error naming the extractor `who` (mesh_id_count) when a row's count or
// a total passes what 32-bit ids hold; throws Cancelled when `progress` is cancelled.
template <size_t Kinds, class Tally>
RowIds<Kinds> count_rows(int64_t ny, int64_t nz, const char* who, Progress& progress,
                         Tally&& tally) {
  RowIds<Kinds> ids;
  ids.ny = ny;
  ids.counts.assign(static_cast<size_t>(ny * nz), RowCount<Kinds>{});
  row_passes_detail::parallel_rows(
      ny, nz, progress,
      [&](int64_t j, int64_t k, size_t r) {
        const RowTally<Kinds> t = tally(j, k);
        RowCount<Kinds>& c = ids.counts[r];
        for (size_t q = 0; q < Kinds; ++q) c.vertices[q] = mesh_id_count(t.vertices[q], who);
        c.triangles = mesh_id_count(t.triangles, who);
      },
      [](size_t) {});
  ids.vertex_first.assign(ids.counts.size() + 1, 0);
  ids.triangle_first.assign(ids.counts.size() + 1, 0);
  uint64_t vertices = 0, triangles = 0;
  for (size_t r = 0; r < ids.counts.size(); ++r) {
    for (uint32_t n : ids.counts[r].vertices) vertices += n;
    triangles += ids.counts[r].triangles;
    ids.vertex_first[r + 1] = mesh_id_count(vertices, who);
    ids.triangle_first[r + 1] = mesh_id_count(triangles, who);
  }
  return ids;
}

// The filling pass: fill(j, k, r) for every row, in parallel, reporting the fraction of rows done
// to `progress` after each block of rows; throws Cancelled when `progress` is cancelled.
template <class Fill>
void fill_rows(int64_t ny, int64_t nz, Progress& progress, Fill&& fill) {
  std::atomic<int64_t> rows_done{0};
  const double rows = double(ny * nz);
  row_passes_detail::parallel_rows(ny, nz, progress, fill, [&](size_t block) {
    progress.update(double(rows_done += int64_t(block)) / rows);
  });
}

// The ids of the cut edges of the cells of row j of slab k, cell after cell: the next cut edge
// not yet passed of the x-edges of rows (j + y, k + z) for cell edges b = y + 2z, of the y-edges of
// rows (j, k + h) and of the z-edges of rows (j + h, k), each at the cell's left (x) and right
// (x + 1). The rows must exist (j + 1 < ny, k + 1 < nz).
struct CutEdgeCursors {
  uint32_t x[4], y[2], z[2];
};

template <size_t Kinds>
CutEdgeCursors cut_edge_cursors(const RowIds<Kinds>& ids, int64_t j, int64_t k) {
  CutEdgeCursors c;
  for (int b = 0; b < 4; ++b) c.x[b] = first_id(ids, row_of(ids.ny, j + (b & 1), k + (b >> 1)), 0);
  for (int h = 0; h < 2; ++h) c.y[h] = first_id(ids, row_of(ids.ny, j, k + h), 1);
  for (int h = 0; h < 2; ++h) c.z[h] = first_id(ids, row_of(ids.ny, j + h, k), 2);
  return c;
}

// Writes the ids of the 12 edges of the row's next cell that is not all inside or all outside
// (marching_cubes_table.hpp numbering; bit e of `cut` set when edge e is cut) to id[0..11], and
// moves the cursors past its cut edges. The ids of edges that are not cut are meaningless.
inline void cut_edge_ids(CutEdgeCursors& c, unsigned cut, uint32_t* id) {
  for (int b = 0; b < 4; ++b) {
    id[b] = c.x[b];
    c.x[b] += cut >> b & 1;
  }
  for (int h = 0; h < 2; ++h) {
    const uint32_t left_y = cut >> (4 + 2 * h) & 1, left_z = cut >> (8 + 2 * h) & 1;
    id[4 + 2 * h] = c.y[h];
    id[5 + 2 * h] = c.y[h] + left_y;
    c.y[h] += left_y;
    id[8 + 2 * h] = c.z[h];
    id[9 + 2 * h] = c.z[h] + left_z;
    c.z[h] += left_z;
  }
}

}  // namespace segmesh
