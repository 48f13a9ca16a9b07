#include "segmesh_viewer/save_scene.hpp"

#include "segmesh/error.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/write_mesh.hpp"

namespace segmesh::viewer {

void save_scene_glb(const ViewerState& state, const std::filesystem::path& file) {
  if (mesh_format_from_path(file) != MeshFormat::glb) {
    throw Error(file.string() + ": the scene is saved as binary glTF; name it *.glb");
  }
  if (state.scene.parts.empty()) throw Error(file.string() + ": there is no scene to save; open a file first");
  write_scene(state.scene, file, MeshFormat::glb);
}

}  // namespace segmesh::viewer
