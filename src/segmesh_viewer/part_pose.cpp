#include "segmesh_viewer/part_pose.hpp"

#include <cmath>
#include <numbers>

#include "segmesh_render/mat4.hpp"

namespace segmesh::viewer {

namespace {

Transform translation(Vec3d t) {
  Transform m = identity_transform();
  m[12] = t.x;
  m[13] = t.y;
  m[14] = t.z;
  return m;
}

// Rotation by `deg` about the world axis `axis` (0 x, 1 y, 2 z), column-major.
Transform rotation(int axis, double deg) {
  const double a = deg * std::numbers::pi / 180;
  const double c = std::cos(a), s = std::sin(a);
  Transform m = identity_transform();
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // the plane turned: u towards v
  m[4 * u + u] = c;
  m[4 * u + v] = s;
  m[4 * v + u] = -s;
  m[4 * v + v] = c;
  return m;
}

}  // namespace

Transform pose_transform(const PartPose& pose, Vec3d pivot, const Transform& base) {
  using render::operator*;
  const Transform turn = rotation(2, pose.rotation_deg.z) * rotation(1, pose.rotation_deg.y) *
                         rotation(0, pose.rotation_deg.x);
  return translation(pose.translation_mm + pivot) * turn * translation(-1.0 * pivot) * base;
}

Vec3d drag_translation(const render::Camera& camera, int viewport_height, double dx_pixels,
                       double dy_pixels, Vec3d at) {
  if (viewport_height <= 0) return {0, 0, 0};
  const render::CameraFrame f = render::camera_frame(camera);
  const double depth = dot(at - f.eye, f.forward);
  if (!(depth > 0)) return {0, 0, 0};
  const double mm_per_pixel =
      2 * depth * std::tan(camera.fov_y_deg * std::numbers::pi / 360) / viewport_height;
  return (dx_pixels * mm_per_pixel) * f.right - (dy_pixels * mm_per_pixel) * f.up;
}

Vec3d moved_pivot(const PartView& view) { return view.pivot + view.pose.translation_mm; }

}  // namespace segmesh::viewer
