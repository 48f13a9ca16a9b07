// PLY reader: ASCII, binary little-endian and binary big-endian.
//
// Reads the "vertex" element's x y z (any scalar type), nx ny nz and red green blue [alpha]
// (or diffuse_red ...; uchar, or floats in 0..1) when present, and the "face" element's
// vertex_indices (or vertex_index) list; polygons are split into triangle fans, other elements and
// properties are skipped. Files written by segmesh carry one "comment part ..." line per part (see
// ply_writer.hpp) and are split back into those parts with their names, labels, roles and
// materials; any other file is one Part named after the file's stem.
//
// Validation: the header is checked before any allocation (every element count against the bytes
// left, at their smallest possible encoding), every read is bounds-checked and every index must be
// below the vertex count. A lying or truncated file is a one-line segmesh::Error naming the file.
// Cost: one pass over the data.
#pragma once

#include <filesystem>
#include <string_view>

#include "segmesh/scene.hpp"

namespace segmesh {

// `bytes` is the whole file; `file` names it in error messages and gives the default part name.
Scene read_ply(std::string_view bytes, const std::filesystem::path& file);

}  // namespace segmesh
