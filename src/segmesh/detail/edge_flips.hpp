// Edge flips that improve the shape of a labelled surface's triangles (decimation.hpp's last
// step): an edge between two triangles of one interface (the same (inside, outside) materials,
// no other triangle on the edge, so never a junction curve's edge) is replaced by the other
// diagonal of its two triangles when
//   - the smaller radii ratio of the two triangles grows (quality.hpp),
//   - the other diagonal is not already an edge of the surface (so no shell gets a doubled edge
//     or a vertex of two triangles),
//   - neither new triangle's normal turns by more than 60 degrees from the old ones' sum, and
//   - the surface moves little: the distance between the two diagonals' lines (the height of
//     the tetrahedron they span) is at most `tolerance_mm`.
// A flip changes both parts' shells of a contact alike, so contacts stay shared; it moves no
// vertex. Passes run over the edges in vertex order, an edge skipped when one of its triangles
// was flipped earlier in the pass, until a pass flips nothing or after kEdgeFlipPasses passes.
// Serial and deterministic. Cost: one sort of the edges per pass.
#pragma once

#include <cstdint>

#include "segmesh/labelled_surface.hpp"

namespace segmesh {

inline constexpr int kEdgeFlipPasses = 4;

// Returns how many edges were flipped.
int64_t improve_by_edge_flips(LabelledSurface& surface, double tolerance_mm);

}  // namespace segmesh
