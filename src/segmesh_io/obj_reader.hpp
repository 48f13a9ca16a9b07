// Wavefront OBJ reader (with its MTL materials).
//
// Reads v (and the common "v x y z r g b" colour extension), vn, f with any of the index forms
// a, a/b, a//c, a/b/c (negative = relative), polygons as triangle fans; vt, l, p, s and the like
// are ignored. Each "o" starts a new Part (each "g" too, when the file has no "o" at all), named
// after it; a file without either is one Part named after the file's stem. A part's vertices are
// the distinct (position, normal) pairs its faces use, in the order the file lists them, so an
// OBJ written by segmesh reads back with the same vertex order and indices. A part has normals
// (colours) only when every corner has one. The first "usemtl" of a part picks its material from
// the "mtllib" files beside the OBJ (Kd, Pr roughness, Pm metallic; a missing MTL file leaves the
// default grey). segmesh's "# segmesh part label=... role=..." comments restore the label,
// component, role, voxel count and visibility.
//
// Validation: every index must name a vertex (normal) defined before it; malformed numbers and
// faces with fewer than 3 corners are a one-line segmesh::Error naming the file and line. Memory
// grows only with what the file actually holds. Cost: one pass over the text.
#pragma once

#include <filesystem>
#include <string_view>

#include "segmesh/scene.hpp"

namespace segmesh {

// `bytes` is the whole file; `file` names it in messages and locates the MTL files.
Scene read_obj(std::string_view bytes, const std::filesystem::path& file);

}  // namespace segmesh
