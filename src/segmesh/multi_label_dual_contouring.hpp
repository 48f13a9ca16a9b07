// Multi-label Dual Contouring: the surfaces of all parts of a label map in one pass, as a dual mesh
// (vertices inside the cells, a polygon per cut grid edge), every contact between two parts (or a
// part and the background) meshed once and shared by both, in the LabelledSurface that joint
// smoothing, decimation and the atlas take from multi-label Marching Cubes.
//
// Each grid point carries a material: the part its voxel belongs to, or the background (0). A grid
// edge whose two ends hold different materials is cut and gets one polygon, of the vertices of its
// four cells around it, tagged {inside, outside} with the pair's winner inside (any part over the
// background, the earlier part over a later one: so every contact is wound one way), wound
// counter-clockwise seen from outside. A cell's vertices:
//   - a binary cell (two materials) gets the vertices of single-label Dual Contouring of the
//     winner's indicator: one per sheet of the winner's case (dual_contouring_table.hpp: the pieces
//     of the cell's Marching Cubes surface, ambiguous faces cut by a chord, the 26-connectivity
//     tube by three), the single sheet's vertex at its QEF minimum (edge midpoints with the
//     indicator's central-difference gradients as normals, svd_eps as given), kept 5 % of a cell
//     inside its cell, several sheets each at its mass point;
//   - a junction cell (three or more materials) gets one vertex per connected piece of its
//     cut edges joined by multi-label Marching Cubes' face rule (material_faces.hpp: two cut
//     edges join when a face segment links them, all of a face's where three or four materials
//     meet at its centre), at the piece's mass point; these are the surface's junction vertices,
//     where part_shells gives a part's shell one vertex per fan.
// The face rule is multi-label Marching Cubes', so neighbouring cells agree and the result is the
// dual of that surface with each cell's pieces contracted to a point.
//
// Guarantees: the two sides of every contact are the same triangles, wound one way; the shells
// part_shells cuts are wound outwards, and closed, edge- and vertex-manifold on everything tested
// (random fields of up to six labels, checkerboards, the phantom, ../shared/data; a shared edge
// whose pairing walk is blocked at both ends would stay doubled: never met). Where a part reaches
// a face shared by two junction cells through two separate segments, the pieces on both sides hold
// both and the part's two sheets share the edge between them; part_shells parts them there
// (labelled_surface.hpp), which can part the shell across a join of the face rule (one handle fewer
// than multi-label Marching Cubes: measured once on the coarse phantom of the tests). Part against
// background only, the shell is single-label Dual Contouring's (the same triangles; vertices from
// the same solve). Vertex normals are not computed.
// Cost: O(runs + surface) time for the cells, which come from merging the runs of four rows of
// voxels (material_rows.hpp), so the interior of a part and the empty space cost nothing. A binary
// cell's neighbourhood key comes from every part's inside bits on its own box, one bit per point
// of each part's box (at most half a byte per point of the parts' common box, else from the runs
// of the twelve rows around it: detail/dc_material_keys.hpp); memory that plus O(runs), 24 bytes
// per cut cell and the output. Parallel over slabs of cells; the output is the same for any
// thread count.
#pragma once

#include <cstddef>
#include <span>

#include "segmesh/components.hpp"
#include "segmesh/dual_contouring.hpp"
#include "segmesh/grid.hpp"
#include "segmesh/labelled_surface.hpp"
#include "segmesh/progress.hpp"

namespace segmesh {

// `parts[p]` indexes components.components and becomes material p + 1. Uses options.connectivity
// (6, 18 or 26) and options.svd_eps; the Hermite normals are central differences whatever
// options.normals says, and options.tolerance_mm (simplification) is not applied. Checks
// cancellation once per slab of cells.
LabelledSurface multi_label_dual_contouring(const Grid& grid, const Components& components,
                                            std::span<const size_t> parts, const DcOptions& options,
                                            Progress& progress = null_progress());

}  // namespace segmesh
