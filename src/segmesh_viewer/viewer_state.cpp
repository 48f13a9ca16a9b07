#include "segmesh_viewer/viewer_state.hpp"

#include <algorithm>

#include "segmesh_render/camera.hpp"

namespace segmesh::viewer {

bool operator==(const PartPose& a, const PartPose& b) {
  const auto same = [](Vec3d u, Vec3d v) { return u.x == v.x && u.y == v.y && u.z == v.z; };
  return same(a.translation_mm, b.translation_mm) && same(a.rotation_deg, b.rotation_deg);
}

void set_scene(ViewerState& state, Scene scene, std::vector<PartStats> stats, std::string source,
               std::shared_ptr<const Image> image) {
  if (stats.size() != scene.parts.size()) stats = measure_parts(scene);
  state.views.assign(scene.parts.size(), PartView{});
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    const Part& part = scene.parts[i];
    state.views[i].base = part.transform;
    const render::Bounds placed =
        render::transformed_bounds(render::mesh_bounds(part.mesh), part.transform);
    if (!placed.empty()) state.views[i].pivot = placed.center();
  }
  state.scene = std::move(scene);
  state.stats = std::move(stats);
  state.selected = -1;
  state.history = {};
  state.source = std::move(source);
  state.image = std::move(image);
  state.surfaces.clear();
}

void select_part(ViewerState& state, int index) {
  state.selected = index >= 0 && size_t(index) < state.scene.parts.size() ? index : -1;
}

void set_visible(ViewerState& state, size_t index, bool visible) {
  if (index >= state.scene.parts.size()) return;
  state.scene.parts[index].visible = visible;
  if (!visible && state.selected == int(index)) state.selected = -1;
}

void set_opacity(ViewerState& state, size_t index, float opacity) {
  if (index >= state.views.size()) return;
  state.views[index].opacity = std::clamp(opacity, 0.0f, 1.0f);
}

void set_color(ViewerState& state, size_t index, Rgb color) {
  if (index >= state.scene.parts.size()) return;
  state.scene.parts[index].material.base_color = color;
}

std::vector<float> render_opacity(const ViewerState& state) {
  std::vector<float> opacity(state.views.size());
  for (size_t i = 0; i < state.views.size(); ++i) opacity[i] = state.views[i].opacity;
  return opacity;
}

void set_message(ViewerState& state, std::string message, bool error) {
  state.message = std::move(message);
  state.message_is_error = error;
}

}  // namespace segmesh::viewer
