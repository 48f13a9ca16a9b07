// Binary STL writer.
//
// Layout: an 80-byte header "segmesh <name> LPS mm" (never starting with "solid", so no reader
// mistakes it for ASCII STL), a uint32 triangle count, then per triangle a float32 face normal
// computed from the triangle's corners (counter-clockwise = outside), three float32 corners and a
// zero uint16 attribute. All parts' triangles go into one solid; STL has no names, materials or
// shared vertices, so read_mesh() welds identical positions to recover the topology.
// Coordinates are world millimetres, LPS; a moved part is written where it was moved to.
// Cost: one pass over the triangles, 50 bytes each, streamed in pieces formatted in parallel
// (mesh_io::write_pieces).
#pragma once

#include <ostream>
#include <string_view>

#include "segmesh_io/part_list.hpp"

namespace segmesh {

// Throws segmesh::Error when the scene has more than 2^32 - 1 triangles.
void write_stl(const mesh_io::PartList& parts, std::ostream& out, std::string_view name);

}  // namespace segmesh
