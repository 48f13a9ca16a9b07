#include "segmesh_viewer/surfaces_summary.hpp"

namespace segmesh::viewer {

std::string surfaces_summary(const Scene& scene, const PipelineStats& pipeline,
                             const MeshingOptions& request) {
  if (scene.surface) return "conforming surfaces: touching parts share their contacts";
  if (scene.conforming) {
    return "conforming surfaces: no parts touch, so each part was meshed on its own";
  }
  if (!pipeline.parts_touch) return "independent surfaces: no parts touch";
  if (const auto note = surfaces_note(request)) return "independent surfaces: " + *note;
  return "independent surfaces: touching parts each have their own surface";
}

}  // namespace segmesh::viewer
