#include "segmesh_io/mesh_format.hpp"

#include <algorithm>
#include <cctype>
#include <string>

namespace segmesh {

std::optional<MeshFormat> parse_mesh_format(std::string_view name) {
  if (!name.empty() && name.front() == '.') name.remove_prefix(1);
  std::string lower(name);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower == "stl") return MeshFormat::stl;
  if (lower == "ply") return MeshFormat::ply;
  if (lower == "obj") return MeshFormat::obj;
  if (lower == "glb") return MeshFormat::glb;
  return std::nullopt;
}

std::optional<MeshFormat> mesh_format_from_path(const std::filesystem::path& path) {
  const std::string ext = path.extension().string();
  if (ext.empty()) return std::nullopt;
  return parse_mesh_format(ext);
}

std::string_view extension(MeshFormat format) {
  switch (format) {
    case MeshFormat::stl: return "stl";
    case MeshFormat::ply: return "ply";
    case MeshFormat::obj: return "obj";
    case MeshFormat::glb: return "glb";
  }
  return "stl";
}

}  // namespace segmesh
