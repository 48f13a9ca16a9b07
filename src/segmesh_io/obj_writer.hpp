// Wavefront OBJ + MTL writer.
//
// scene.obj holds "mtllib scene.mtl", then per part a comment with its label, component, role,
// voxels and visibility ("# segmesh part label=1 component=1 role=bone voxels=0 visible=1"),
// "o <name>", "usemtl <material>", its vertices "v x y z", normals "vn x y z" when it has them,
// and triangles "f a//a b//b c//c" (or "f a b c") with 1-based indices global over the file.
// scene.mtl holds one material per part, named after the part (whitespace replaced by '_', made
// unique): Kd the base colour, Ks/Ns a Blinn-Phong approximation for old readers, and the PBR
// extension keys Pr (roughness) and Pm (metallic). Numbers are written in their shortest exact
// form, so positions read back bit-identical. Coordinates are world millimetres, LPS; a moved part
// is written where it was moved to. Cost: one pass, text formatted with std::to_chars in pieces
// in parallel (mesh_io::write_pieces).
#pragma once

#include <ostream>
#include <string>

#include "segmesh_io/part_list.hpp"

namespace segmesh {

// `mtl_file_name` is what the OBJ's mtllib line names (the MTL file beside it).
void write_obj(const mesh_io::PartList& parts, std::ostream& obj, std::ostream& mtl,
               const std::string& mtl_file_name);

}  // namespace segmesh
