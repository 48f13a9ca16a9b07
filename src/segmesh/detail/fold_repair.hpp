// Fold repair after joint smoothing: where smoothing folded the shared surface near a junction
// curve (a sheet pulled across a fixed junction corner: measured on the phantom where the two
// bone fragments, the plate and the background meet, with 4 mm slices), the vertices of every
// crossing pair of triangles go back toward their extracted positions until nothing crosses.
//
// Only the triangles near the junctions are examined (every corner within `reach` edges of a
// junction curve): away from them one interface is smoothed as a single mesh is. A round
// finds every pair of those triangles (sharing no vertex) where an edge of one passes through
// the interior of the other, halves the displacement of the pair's six vertices (from the
// extracted position to the smoothed one), and looks again; after kFoldRounds rounds the
// vertices still involved take their extracted positions, where nothing crossed. Vertices move
// on the one shared surface, so contacts stay exact.
// Cost: one pass over the triangles, then per round one uniform-grid pass over the examined
// triangles (a few per cent of all; after the first round only pairs with a moved vertex).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/detail/smoothing_filters.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

inline constexpr int kFoldRounds = 6;

// mesh.positions are the smoothed positions, `extracted` the positions before smoothing, `role`
// the vertices' smoothing roles, `reach` the rings around the junctions examined
// (LabelledSurface::fold_reach). Returns how many vertices were moved back.
size_t repair_folds(TriMesh& mesh, const std::vector<Vec3f>& extracted,
                    const std::vector<SmoothRole>& role, int reach = 1);

// Whether the segment [p, q] passes through the interior of triangle (a, b, c): through its
// plane strictly between its ends, at a point strictly inside (margins of 1e-6 relative), so a
// shared edge or corner, or a coplanar pair, does not count.
bool segment_crosses_triangle(Vec3d p, Vec3d q, Vec3d a, Vec3d b, Vec3d c);

}  // namespace segmesh
