// Binary little-endian PLY writer.
//
// Vertex properties: float x y z; float nx ny nz when every part has normals; uchar red green blue
// alpha when any part has per-vertex colours or the scene has several parts (a part without
// colours then gets its material colour on every vertex, so parts stay distinguishable in viewers
// that show vertex colours). Faces: "property list uchar uint vertex_indices", triangles only.
// All parts share one vertex and one face list, part after part; the header's comments say
// "space LPS", "units mm" and, per part, its vertex and face ranges, label, role and material, so
// read_mesh() splits the file back into parts:
//   comment part vertices=8 faces=12 label=1 component=1 role=bone voxels=0 visible=1
//           color=0.95,0.93,0.88 metallic=0 roughness=0.6 name=left tibia
// Coordinates are world millimetres, LPS; a moved part is written where it was moved to.
// Cost: one pass, 12-28 bytes per vertex and 13 per triangle, streamed in pieces formatted in
// parallel (mesh_io::write_pieces); a moved part is transformed as it is written, not copied.
// The first header lines and the vertex records are detail/ply_layout.hpp's.
#pragma once

#include <ostream>

#include "segmesh_io/part_list.hpp"

namespace segmesh {

void write_ply(const mesh_io::PartList& parts, std::ostream& out);

}  // namespace segmesh
