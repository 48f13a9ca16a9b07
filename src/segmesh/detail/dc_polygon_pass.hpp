// Dual Contouring's polygon passes over the rows of cells (dc_cell_rows.hpp): pricing the
// polygons next to rare cells before the prefix sums, and writing every polygon's triangles once
// the vertices are placed.
#pragma once

#include "segmesh/detail/dc_cell_rows.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh::dc {

// Pass 2, in parallel over rows: the triangles per row corrected where a polygon next to a rare
// cell is not a quad, and the centroid vertices (into extra_first[r + 1]); the rows that own a
// cut edge without its four cells throw std::logic_error. Only the rows next to a rare cell, or
// short, are looked at. Runs on the counts, before prefix_sums: the polygons' vertex ids are not
// known yet, and their cost only depends on their shape. `mirrored`: the grid mirrors.
void count_polygons(CellRows& rows, bool mirrored, Progress& progress);

// Pass 4, in parallel over rows: every owned cut edge's polygon split into triangles at the
// row's triangle_first, centroid vertices at its extra_first after the sheets. `mesh` comes sized
// (positions, normals when wanted, indices) with its sheet vertices placed. Reports progress
// from 0.5 to 1.
void emit_polygons(const CellRows& rows, bool mirrored, TriMesh& mesh, Progress& progress);

}  // namespace segmesh::dc
