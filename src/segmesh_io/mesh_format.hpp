// MeshFormat: the surface mesh file formats segmesh writes and reads.
//
//   stl  binary STL (writes); binary or ASCII STL (reads)
//   ply  binary little-endian PLY (writes); binary LE/BE or ASCII PLY (reads)
//   obj  Wavefront OBJ with an MTL material file beside it
//   glb  binary glTF 2.0
#pragma once

#include <filesystem>
#include <optional>
#include <string_view>

namespace segmesh {

enum class MeshFormat { stl, ply, obj, glb };

// The format named by the file's extension (".stl", ".PLY", ...), case-insensitive; nullopt when
// the extension is none of them.
std::optional<MeshFormat> mesh_format_from_path(const std::filesystem::path& path);

// "stl", "ply", "obj" or "glb" (case-insensitive, an optional leading dot allowed); nullopt for
// anything else.
std::optional<MeshFormat> parse_mesh_format(std::string_view name);

// The format's file extension without the dot: "stl", "ply", "obj", "glb".
std::string_view extension(MeshFormat format);

}  // namespace segmesh
