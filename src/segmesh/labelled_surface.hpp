// LabelledSurface: the surface of every part of a label map at once, each contact between two
// parts meshed once and shared by both ("atlas"), and the per-part shells cut from it.
//
// A triangle separates two materials: 0 is the background (everything no part holds), p + 1 is
// the scene's part p. Each triangle records its (inside, outside) pair and is wound counter-
// clockwise seen from its outside side, so its normal points from inside to outside. Where two
// parts touch, their common surface is one set of triangles on one set of vertices; where three
// or more materials meet (a junction curve: implant, bone and background along a plate's rim)
// the triangles of the different pairs share the curve's vertices. The surface as a whole is not
// a manifold (junction edges carry three or more triangles); each part's shell is.
//
// part_shells cuts one closed, edge-manifold, outward-wound mesh per part out of it: the part's
// triangles, those where the part is outside turned around, on the part's vertices only. Where a
// part's shell touches itself at a junction vertex (its material reaches a junction cell from two
// sides), the shell gets one vertex per fan there, at the same position, so it stays a manifold.
// Where two sheets of a shell share an edge between two junction vertices (four triangles on it:
// multi-label Dual Contouring contracts each junction cell's piece to one vertex, and a part that
// reaches a face through two separate segments gives the pieces on both sides both sheets), the
// edge's triangles are paired by sheet (walking round one end over its other edges) and the fans
// part there too: the shell touches itself along that edge, as two edges at the same place.
// Cost: O(vertices + triangles) time and the shells' memory (the junction vertices' triangles
// sorted; a walk per shared edge).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "segmesh/tri_mesh.hpp"

namespace segmesh {

struct LabelledSurface {
  TriMesh mesh;  // world millimetres, vertices shared between the parts
  // Per triangle: {inside, outside} material (0 background, p + 1 part p).
  std::vector<std::array<uint32_t, 2>> sides;
  // The vertices at which a part's shell can touch itself (junction cells' centres or pieces),
  // ascending.
  std::vector<uint32_t> junction_vertices;
  size_t part_count = 0;
  // How many rings of triangles around the junction curves the joint smoothing's fold repair
  // examines (detail/fold_repair.hpp): 1 for Marching Cubes (every fold measured on the phantom
  // had a junction corner); 2 for Dual Contouring, whose junction vertices sit at their pieces'
  // mass points and whose sheets folded two rings out on the 3 mm TotalSegmentator map. Each ring
  // more adds triangles to every round of the repair.
  int fold_reach = 1;
};

// Whether two triangles' sides are one interface: the same two materials, wound either way
// ((1, 2) beside (2, 1): multi-label Marching Cubes makes both along one contact).
inline bool same_interface(const std::array<uint32_t, 2>& a, const std::array<uint32_t, 2>& b) {
  return a == b || (a[0] == b[1] && a[1] == b[0]);
}

// The closed shell of every part, in part order; vertex normals when the surface has them
// (turned around with the triangles where the part is outside). With `origin`, also each shell
// vertex's surface vertex ((*origin)[p][i] for shell p's vertex i; a vertex split where a shell
// touches itself gives several shell vertices one surface vertex). The cut depends only on the
// triangles, so a surface whose vertices moved (smoothing) is cut into the same vertices.
using ShellOrigins = std::vector<std::vector<uint32_t>>;
std::vector<TriMesh> part_shells(const LabelledSurface& surface, ShellOrigins* origin = nullptr);

// One pair of touching parts (materials a < b) and the area of their common surface.
struct PartContact {
  uint32_t a = 0, b = 0;
  double area_mm2 = 0;
};

// The contacts between parts (not the background), ordered by (a, b).
std::vector<PartContact> part_contacts(const LabelledSurface& surface);

}  // namespace segmesh
