// What the PLY writers share (ply_writer: the parts; atlas_writer: the conforming surface):
// the header's first lines and the vertex element, in binary little-endian. Internal to
// segmesh_io.
//
// A vertex is float x y z, then float nx ny nz and uchar red green blue alpha when the layout has
// them: 12, 24, 16 or 28 bytes. Positions are written as the mesh holds them (world millimetres,
// LPS), moved by the Placement as they are written. Cost: one pass over the vertices, formatted
// in pieces in parallel (piece_writer.hpp).
#pragma once

#include <cstddef>
#include <string>

#include "segmesh/tri_mesh.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"

namespace segmesh::mesh_io {

// "ply", the format line and the comments every segmesh PLY starts with (generator, SPACE=LPS,
// units mm), each ending in a line break.
std::string ply_header_start();

struct PlyVertexLayout {
  bool normals = false;
  bool colors = false;
  size_t bytes() const { return 12 + (normals ? 12 : 0) + (colors ? 4 : 0); }
};

// "element vertex <count>" and the property lines of `layout`.
std::string ply_vertex_element(size_t count, PlyVertexLayout layout);

// The vertices of `mesh` as records of `layout`, moved by `placement`; with colours, a mesh
// without any gets `fill` on every vertex. The mesh must outlive pieces.write().
void add_ply_vertices(PieceList& pieces, const TriMesh& mesh, const Placement& placement,
                      PlyVertexLayout layout, Rgba8 fill = {255, 255, 255, 255});

}  // namespace segmesh::mesh_io
