#include "segmesh_viewer/view_controls.hpp"

#include <cmath>

namespace segmesh::viewer {

void apply_view_key(render::Camera& camera, ViewKey key) {
  switch (key) {
    case ViewKey::left: render::orbit(camera, kKeyOrbitStepDeg, 0); break;
    case ViewKey::right: render::orbit(camera, -kKeyOrbitStepDeg, 0); break;
    case ViewKey::up: render::orbit(camera, 0, kKeyOrbitStepDeg); break;
    case ViewKey::down: render::orbit(camera, 0, -kKeyOrbitStepDeg); break;
    case ViewKey::zoom_in: render::zoom(camera, kKeyZoomFactor); break;
    case ViewKey::zoom_out: render::zoom(camera, 1 / kKeyZoomFactor); break;
  }
}

void drag_orbit(render::Camera& camera, double dx_pixels, double dy_pixels) {
  render::orbit(camera, -dx_pixels * kDragOrbitDegPerPixel, dy_pixels * kDragOrbitDegPerPixel);
}

void wheel_zoom(render::Camera& camera, double notches) {
  render::zoom(camera, std::pow(kWheelZoomFactor, notches));
}

void fit_scene(render::Camera& camera, const Scene& scene, double aspect) {
  render::Bounds bounds = render::scene_bounds(scene);
  if (bounds.empty()) bounds = render::scene_bounds(scene, true);
  render::fit(camera, bounds, aspect);
}

void show_standard_view(render::Camera& camera, const Scene& scene, render::StandardView view,
                        double aspect) {
  render::set_view(camera, view);
  fit_scene(camera, scene, aspect);
}

}  // namespace segmesh::viewer
