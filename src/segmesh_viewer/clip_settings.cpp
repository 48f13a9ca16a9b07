#include "segmesh_viewer/clip_settings.hpp"

#include <algorithm>

namespace segmesh::viewer {

std::optional<render::ClipPlane> clip_plane(const ClipSettings& settings, const Scene& scene) {
  if (!settings.enabled) return std::nullopt;
  const render::Bounds bounds = render::scene_bounds(scene, true);
  if (bounds.empty()) return std::nullopt;
  const int axis = std::clamp(settings.axis, 0, 2);
  const double t = std::clamp(double(settings.position), 0.0, 1.0);
  const double lo[3] = {bounds.min.x, bounds.min.y, bounds.min.z};
  const double hi[3] = {bounds.max.x, bounds.max.y, bounds.max.z};
  double point[3] = {bounds.center().x, bounds.center().y, bounds.center().z};
  point[axis] = lo[axis] + t * (hi[axis] - lo[axis]);
  double normal[3] = {0, 0, 0};
  normal[axis] = settings.flip ? -1 : 1;
  return render::ClipPlane{{point[0], point[1], point[2]}, {normal[0], normal[1], normal[2]}};
}

}  // namespace segmesh::viewer
