// Reading surface meshes back into a Scene: STL (binary and ASCII), PLY (binary little/big-endian
// and ASCII), OBJ (with its MTL) and binary glTF (.glb).
//
// The format is recognised from the content (the "glTF" and "ply" magics) and otherwise from the
// extension (.stl, .obj; an unknown extension falls back to STL when the content fits). One Part
// per object: STL one per solid, PLY one per part comment written by segmesh (else one), OBJ one
// per "o" (or "g"), GLB one per node with a mesh. Vertices are shared: STL welds identical
// positions, the others keep the file's indexing. Names, materials, labels and roles come back
// when the file carries them (PLY comments, OBJ/MTL, GLB extras); otherwise a part is named after
// the file's stem with a neutral grey material. Scene::grid is left at its default: mesh files do
// not record the source volume. Details and limits: stl_reader.hpp, ply_reader.hpp,
// obj_reader.hpp, gltf_reader.hpp.
//
// Guarantees: every count in a header is checked against the file's size before memory is
// allocated for it, and every index against the vertex count; a missing, truncated, lying or
// unsupported file is a one-line segmesh::Error that names the file, never a crash or a huge
// allocation. Cost: the file is read into memory once, then parsed in one pass.
#pragma once

#include <filesystem>

#include "segmesh/scene.hpp"

namespace segmesh {

Scene read_mesh(const std::filesystem::path& file);

}  // namespace segmesh
