// The geometry of a part's move: a PartPose (rotation about the part's centre, then a translation)
// as the 4x4 rigid Transform the renderer and the GLB writer use, and the translation that makes
// a part follow the mouse in the view plane.
//
//   transform = T(translation) * T(pivot) * Rz * Ry * Rx * T(-pivot) * base
//
// `base` is the transform the part was loaded with (identity for meshed volumes, a GLB node's
// matrix for a saved scene), `pivot` the centre of the placed part's bounds, so a rotation turns
// the part in place. Column-major doubles, as segmesh::Transform.
#pragma once

#include "segmesh/scene.hpp"
#include "segmesh/vec3.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_viewer/viewer_state.hpp"

namespace segmesh::viewer {

Transform pose_transform(const PartPose& pose, Vec3d pivot, const Transform& base);

// The world translation that moves a point at `at` with the mouse by (dx, dy) pixels (x right,
// y down) in a viewport `viewport_height` pixels high: a motion in the view plane at the point's
// depth, so the part stays under the cursor. Zero for a point behind the eye or a zero height.
Vec3d drag_translation(const render::Camera& camera, int viewport_height, double dx_pixels,
                       double dy_pixels, Vec3d at);

// The world position of the part's pivot after its current move (where the part is now).
Vec3d moved_pivot(const PartView& view);

}  // namespace segmesh::viewer
