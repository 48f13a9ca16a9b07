// Multi-label Marching Cubes: the surfaces of all parts of a label map in one pass, every contact
// between two parts (or a part and the background) meshed once, its vertices shared by both.
//
// Each grid point carries a material: the part its voxel belongs to, or the background. A cell
// whose eight corners hold
//   - one material holds no surface;
//   - two materials is a binary cell: the Marching Cubes case (marching_cubes_table.hpp) of the
//     material that wins the pair, with its triangles tagged (winner, other). The background loses
//     to every part and, between two parts, the earlier part in the scene wins; the winner plays
//     "inside", so the face rule (ambiguous faces joined under connectivity 18 and 26, separated
//     under 6) and the 26-connectivity tube are today's, and a part against the background gets
//     exactly the triangles independent Marching Cubes gives it;
//   - three or more materials is a junction cell: on each face the cut edges are joined as the
//     face's materials say (a face with two materials as the binary rule; a diagonal pair of one
//     material with two others joins that pair; three or four materials around the face meet at
//     the face's centre), and every face segment is joined to the cell's centre by a triangle
//     tagged with the materials on its two sides.
// Face decisions depend on the face's four corners only, so the two cells sharing a face agree and
// the surface has no cracks, junctions included. Vertices sit at edge midpoints (binary label maps
// carry no sub-voxel position), at junction faces' and cells' centres.
//
// The passes are those of marching_cubes.hpp: rows of cells counted in parallel from the parts'
// runs (material_rows.hpp: no volume of materials is built), prefix sums, disjoint output ranges
// filled in parallel, vertex ids found by cursors per row; the output is the same for any thread
// count. Guarantees: every part's shell (part_shells) is closed, edge-manifold and wound outwards;
// the two sides of every contact are the same triangles. Cost: O(run ends + output) time; memory
// the runs by row, 40 bytes per row and the output.
#pragma once

#include <cstddef>
#include <span>

#include "segmesh/components.hpp"
#include "segmesh/grid.hpp"
#include "segmesh/labelled_surface.hpp"
#include "segmesh/progress.hpp"

namespace segmesh {

// `parts[p]` indexes components.components and becomes material p + 1; connectivity 6, 18 or 26
// (the face rule above). Checks cancellation once per block of rows and reports its progress.
LabelledSurface multi_label_marching_cubes(const Grid& grid, const Components& components,
                                           std::span<const size_t> parts, int connectivity,
                                           Progress& progress = null_progress());

}  // namespace segmesh
