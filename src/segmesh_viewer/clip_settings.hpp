// The clipping panel: a plane across one world axis (x left-right, y anterior-posterior, z
// inferior-superior) at a position given as a fraction of the scene's extent along that axis,
// keeping the side the normal points into (flip keeps the other side). Converted to the
// renderer's ClipPlane (renderer.hpp), which cuts every part and hatches the cut surfaces.
#pragma once

#include <optional>

#include "segmesh/scene.hpp"
#include "segmesh_render/renderer.hpp"

namespace segmesh::viewer {

struct ClipSettings {
  bool enabled = false;
  int axis = 1;          // 0 x, 1 y, 2 z
  float position = 0.5f; // 0..1 across the bounds of every part (moved, hidden ones included)
  bool flip = false;     // keep the negative side instead
};

// nullopt when disabled or the scene has no vertices.
std::optional<render::ClipPlane> clip_plane(const ClipSettings& settings, const Scene& scene);

}  // namespace segmesh::viewer
