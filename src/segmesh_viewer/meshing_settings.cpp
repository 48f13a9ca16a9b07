#include "segmesh_viewer/meshing_settings.hpp"

namespace segmesh::viewer {

MeshingOptions meshing_request(const MeshingSettings& settings) {
  MeshingOptions options;
  options.method = settings.method;
  options.surfaces = settings.surfaces;
  options.normals = settings.normals;
  options.smooth.method = settings.smooth;
  options.smooth.iterations = settings.iterations;
  options.decimate.error_mm = settings.decimate_error_mm;
  options.decimate.max_triangles = settings.max_triangles;
  // The command line's parser, so the field and `--labels` take the same text.
  find_meshing_option("labels")->set(options, settings.labels);
  resolve_meshing_options(options);  // refuses what would not run, before any work starts
  return options;
}

MeshingOptions meshing_options(const MeshingSettings& settings) {
  return resolve_meshing_options(meshing_request(settings));
}

}  // namespace segmesh::viewer
