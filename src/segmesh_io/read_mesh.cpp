#include "segmesh_io/read_mesh.hpp"

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/gltf_reader.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/obj_reader.hpp"
#include "segmesh_io/ply_reader.hpp"
#include "segmesh_io/stl_reader.hpp"

namespace segmesh {

Scene read_mesh(const std::filesystem::path& file) {
  const std::string bytes = mesh_io::read_whole_file(file);
  if (bytes.starts_with("glTF")) return read_glb(bytes, file);
  if (bytes.starts_with("ply\n") || bytes.starts_with("ply\r\n")) return read_ply(bytes, file);
  const auto format = mesh_format_from_path(file);
  if (format == MeshFormat::obj) return read_obj(bytes, file);
  if (format == MeshFormat::glb) return read_glb(bytes, file);
  if (format == MeshFormat::ply) return read_ply(bytes, file);
  if (format == MeshFormat::stl) return read_stl(bytes, file);
  const bool stl_like = bytes.starts_with("solid") ||
                        (bytes.size() >= 84 &&
                         bytes.size() == 84 + 50 * uint64_t{load_le<uint32_t>(bytes.data() + 80)});
  if (stl_like) return read_stl(bytes, file);
  mesh_io::fail(file, "unknown mesh format; expected an .stl, .ply, .obj or .glb file");
}

}  // namespace segmesh
