// The roles of the vertices of a labelled surface (labelled_surface.hpp), shared by joint
// smoothing and decimation: a vertex all of whose triangles separate the same two materials (an
// interface) is
// a sheet vertex (kSheet); a vertex on two or more interfaces with exactly two junction edges
// (edges whose triangles separate two or more different pairs of materials) lies on a junction
// curve (kCurve); every other vertex on two or more interfaces (where curves meet or end) is
// fixed (kFixed). Also the material of the part each vertex of a part's surface against the
// background belongs to (0 for every other vertex), which joint smoothing's volume restoration
// moves.
//
// Cost: two parallel passes over the triangles (each vertex's interfaces; the triangles with two
// corners on several), two over those triangles and a parallel sort of their edges between
// vertices of two or more interfaces (a small fraction of all edges).
#pragma once

#include <cstdint>
#include <vector>

#include "segmesh/detail/smoothing_filters.hpp"
#include "segmesh/labelled_surface.hpp"

namespace segmesh {

struct SurfaceRoles {
  SmoothTopology smooth;                // role per vertex, the curve edges, the pinned vertices
  std::vector<uint32_t> free_material;  // per vertex: p + 1 on part p's surface against the
                                        // background only, else 0
};

// Whether triangles of the same two materials wound the two ways ((1, 2) and (2, 1): multi-label
// Marching Cubes makes both along one contact) are one interface (either_way) or two (ordered,
// which makes the vertices where the winding changes curve or fixed vertices). Joint smoothing
// and decimation use either_way: with ordered thousands of contact vertices never moved or
// collapsed.
enum class InterfaceSides { ordered, either_way };

SurfaceRoles surface_roles(const LabelledSurface& surface,
                           InterfaceSides kind = InterfaceSides::ordered);

}  // namespace segmesh
