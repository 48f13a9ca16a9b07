// STL reader: binary and ASCII.
//
// A file is binary when its size is exactly 84 + 50 * (the header's triangle count), otherwise
// ASCII when it starts with "solid"; anything else is an Error (a truncated binary file or a lying
// count is caught here, before any allocation). Corners with bit-identical coordinates are welded
// into one shared vertex (+0 and -0 are the same), so a closed mesh written as STL reads back
// closed. Binary STL gives one Part (named from a segmesh header "segmesh <name> LPS mm", else the
// file's stem); ASCII STL gives one Part per "solid ... endsolid" block, named after the solid.
// Face normals and attribute bytes are ignored; parts get no per-vertex normals.
// Cost: one pass plus a hash map over the corners.
#pragma once

#include <filesystem>
#include <string_view>

#include "segmesh/scene.hpp"

namespace segmesh {

// `bytes` is the whole file; `file` names it in error messages and gives the default part name.
Scene read_stl(std::string_view bytes, const std::filesystem::path& file);

}  // namespace segmesh
