// Which kind of surfaces a meshing run made, in one line for the meshing panel: conforming
// (touching parts share their contacts), conforming asked for but no parts touch (each part was
// meshed on its own, which gives the same surfaces), or independent (with the core's
// surfaces_note saying why when automatic surfaces could not be conforming). Taken from what the
// pipeline reports (Scene::conforming, Scene::surface, PipelineStats::parts_touch), not decided
// here.
#pragma once

#include <string>

#include "segmesh/meshing_options.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/scene.hpp"

namespace segmesh::viewer {

// `request` is the options as asked for (before resolve_meshing_options turned automatic into a
// kind), `scene` and `pipeline` what build_scene made of them.
std::string surfaces_summary(const Scene& scene, const PipelineStats& pipeline,
                             const MeshingOptions& request);

}  // namespace segmesh::viewer
