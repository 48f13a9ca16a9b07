#include "segmesh_viewer/load_input.hpp"

#include "segmesh/error.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/read_volume.hpp"
#include "segmesh_viewer/surfaces_summary.hpp"

namespace segmesh::viewer {

InputKind input_kind(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return InputKind::volume;
  return mesh_format_from_path(path) ? InputKind::mesh : InputKind::volume;
}

LoadResult run_load(const LoadRequest& request, Progress& progress) {
  LoadResult result;
  if (request.image) {
    result.image = request.image;
    result.source = request.image->path;
    result.kind = InputKind::volume;
  } else {
    if (request.path.empty()) throw Error("no file to open");
    result.source = request.path.string();
    result.kind = input_kind(request.path);
    progress.step("reading");
    if (result.kind == InputKind::mesh) {
      result.scene = read_mesh(request.path);
      if (result.scene.parts.empty()) throw Error(result.source + ": the file holds no mesh");
    } else {
      result.image = std::make_shared<const Image>(read_volume(request.path));
    }
    throw_if_cancelled(progress);
  }
  if (result.kind == InputKind::volume) {
    PipelineStats pipeline;
    result.scene = build_scene(*result.image, request.meshing, progress, &pipeline);
    result.surfaces = surfaces_summary(result.scene, pipeline, request.meshing);
  }
  result.stats = measure_parts(result.scene, progress);
  return result;
}

}  // namespace segmesh::viewer
