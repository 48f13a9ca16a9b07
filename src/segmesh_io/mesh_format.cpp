#include "segmesh_io/mesh_format.hpp"

#include <string>

#include "segmesh_io/detail/text.hpp"

namespace segmesh {

std::optional<MeshFormat> parse_mesh_format(std::string_view name) {
  if (!name.empty() && name.front() == '.') name.remove_prefix(1);
  const std::string format = lower(std::string(name));
  if (format == "stl") return MeshFormat::stl;
  if (format == "ply") return MeshFormat::ply;
  if (format == "obj") return MeshFormat::obj;
  if (format == "glb") return MeshFormat::glb;
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
