// Joint smoothing of a surface shared by the parts of a label map (labelled_surface.hpp): every
// vertex moves once, for every part it belongs to, so two touching parts stay in contact after
// smoothing, exactly.
//
// The filters are smoothing.hpp's, run on the shared surface with one change in whose neighbours
// a vertex averages:
//   - a vertex inside one interface (all its triangles separate the same two materials: a part
//     and the background, or two parts) averages over its triangles, as on a single mesh;
//   - a vertex on a junction curve (where three or more materials meet: the rim of a plate on a
//     bone) averages over its two neighbours along the curve only, so the curve is smoothed along
//     itself and not pulled into one of the sheets that meet there;
//   - a vertex where junction curves meet or end stays where it is.
// Volume restoration then holds per part: the vertices of a part's surface against the
// background (and no other material) move along their normals by the one offset that gives the
// part back the volume it enclosed before smoothing. Interfaces between parts and junction
// curves are not moved by it, so they stay shared. A part with no surface against the
// background (enclosed by others) keeps the volume smoothing leaves it; one smoothing nearly
// erased (below a quarter of its volume) gets its background vertices back unsmoothed, and after
// the fold repair any part left below a quarter of its volume (a voxel or two enclosed by other
// parts, flattened: met with Dual Contouring on random label noise) gets all its vertices back
// where they were extracted.
//
// Where smoothing folded the surface near a junction (one sheet pulled through another), the
// corners of the crossing triangles go back toward their extracted positions until nothing
// crosses (detail/fold_repair.hpp).
//
// The surface's normals are cleared: part_shells' meshes get their own (compute_vertex_normals).
// Cost: smooth_mesh's on the shared surface, plus one sort of the edges between vertices of two
// or more interfaces (a small fraction of all edges) and one pass over the triangles per part
// count for the volumes.
#pragma once

#include "segmesh/labelled_surface.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/smoothing.hpp"

namespace segmesh {

// Throws std::invalid_argument for options out of range (smooth_options_problem); Cancelled when
// progress is cancelled. SmoothMethod::none leaves the surface as it is.
void smooth_jointly(LabelledSurface& surface, const SmoothOptions& options,
                    Progress& progress = null_progress());

}  // namespace segmesh
