// One part's surface: the one extraction dispatch of the pipeline, over
//   source           a label map's component (its runs) or a grey-value volume's component (the
//                    values around it, other components lowered below iso),
//   method           Marching Cubes (marching_cubes.hpp) or Dual Contouring (dual_contouring.hpp),
//   volume smoothing none, or a Gaussian of the part's field first (gaussian_filter.hpp).
// A label part without volume smoothing is extracted straight from its runs (no mask is built);
// every other combination from the part's field (component_field.hpp). A part that volume
// smoothing would erase (thinner than the kernel) is meshed without it and says so, because a part
// must never silently disappear.
//
// Progress: the extractor's own passes report into `progress` (the Gaussian filter's first half
// when it runs) and check its cancellation once per block of rows, so a large part moves a
// progress bar and stops within a block of work when cancelled.
#pragma once

#include <memory>

#include "segmesh/components.hpp"
#include "segmesh/dual_contouring.hpp"
#include "segmesh/image.hpp"
#include "segmesh/label_stats.hpp"
#include "segmesh/meshing_options.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

// What parts are extracted from: the volume, its components and (grey-value volumes) the value
// range, whose lowest value continues the field outside the volume.
struct PartSource {
  const Image& image;
  const Components& components;
  ValueRange range;
};

struct PartMesh {
  TriMesh mesh;
  bool unsmoothed_fallback = false;  // volume smoothing erased the part: meshed without it
};

// The surface of `component` with the resolved `options` (resolve_meshing_options). `solved`:
// Dual Contouring's neighbourhoods shared by the parts of a scene (make_shared_neighbourhoods),
// or nullptr. Throws Cancelled when progress is cancelled.
PartMesh extract_part(const PartSource& source, const Component& component,
                      const MeshingOptions& options, Progress& progress = null_progress(),
                      DcNeighbourhoods* solved = nullptr);

// The neighbourhood table the parts of one label map share under `options`, or nullptr where
// extract_part does not use one (Marching Cubes, grey values, volume smoothing).
std::unique_ptr<DcNeighbourhoods> make_shared_neighbourhoods(const Grid& grid,
                                                             const MeshingOptions& options);

}  // namespace segmesh
