// How the viewer's keys and mouse turn into camera changes, as plain functions over
// segmesh::render::Camera (camera.hpp owns orbit, pan, zoom, the standard views and fit; this file
// only fixes the viewer's step sizes and what "fit" frames).
//
//   arrow keys   orbit by kKeyOrbitStepDeg: left/right turn the scene left/right (as a left/right
//                drag does), up/down raise/lower the eye
//   + / -        zoom by kKeyZoomFactor (closer / farther)
//   left drag    orbit, kDragOrbitDegPerPixel
//   right or middle drag  pan (the scene follows the mouse)
//   wheel        zoom by kWheelZoomFactor per notch
#pragma once

#include "segmesh/scene.hpp"
#include "segmesh_render/camera.hpp"

namespace segmesh::viewer {

inline constexpr double kKeyOrbitStepDeg = 5;
inline constexpr double kKeyZoomFactor = 1.1;
inline constexpr double kDragOrbitDegPerPixel = 0.4;
inline constexpr double kWheelZoomFactor = 1.15;

enum class ViewKey { left, right, up, down, zoom_in, zoom_out };

void apply_view_key(render::Camera& camera, ViewKey key);

// A mouse drag of (dx, dy) pixels (x right, y down) that orbits: dragging right turns the scene
// right (the eye moves left), dragging down tilts the top of the scene towards the viewer.
void drag_orbit(render::Camera& camera, double dx_pixels, double dy_pixels);

// Wheel notches (positive: away from the user, zooms in).
void wheel_zoom(render::Camera& camera, double notches);

// Frames the visible parts (every part when none is visible) for a viewport of `aspect`, keeping
// the direction of view. Does nothing for a scene without vertices.
void fit_scene(render::Camera& camera, const Scene& scene, double aspect);

// The standard view, framing what fit_scene frames.
void show_standard_view(render::Camera& camera, const Scene& scene, render::StandardView view,
                        double aspect);

}  // namespace segmesh::viewer
