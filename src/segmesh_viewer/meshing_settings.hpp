// The meshing panel's fields and their conversion to MeshingOptions (meshing_options.hpp). The
// defaults are the options layer's (Marching Cubes, automatic surfaces, central-difference
// normals, the default smoothing with its method's iteration count, every label), so "Create
// mesh" without changes gives what `segmesh mesh` gives. The labels field is read by the
// command line's own parser for `--labels` (the option's MeshingOptionSpec), so it takes the
// same text.
#pragma once

#include <string>

#include "segmesh/meshing_options.hpp"

namespace segmesh::viewer {

struct MeshingSettings {
  Method method = MeshingOptions{}.method;
  Surfaces surfaces = MeshingOptions{}.surfaces;  // automatic: conforming where it can be
  NormalMethod normals = MeshingOptions{}.normals;
  SmoothMethod smooth = MeshingOptions{}.smooth.method;
  int iterations = resolve_meshing_options({}).smooth.iterations;
  std::string labels;  // as `--labels` takes them: "1,2"; empty: every non-zero label
  // Decimation after smoothing (`--decimate-error`, `--max-triangles`): 0 leaves it off.
  double decimate_error_mm = MeshingOptions{}.decimate.error_mm;
  int max_triangles = static_cast<int>(MeshingOptions{}.decimate.max_triangles);
};

// The request these settings make (everything else at the defaults), as a front end hands it to
// build_scene: not resolved, so surfaces_note can still say why automatic surfaces were not
// conforming. Throws segmesh::Error when it would not resolve: labels that do not parse
// ("--labels expects whole numbers like 1,2"), options out of range (a negative iteration count,
// a negative decimation error or budget).
MeshingOptions meshing_request(const MeshingSettings& settings);

// The resolved options for these settings: resolve_meshing_options(meshing_request(settings)).
MeshingOptions meshing_options(const MeshingSettings& settings);

}  // namespace segmesh::viewer
