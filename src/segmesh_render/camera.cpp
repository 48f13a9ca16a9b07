#include "segmesh_render/camera.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace segmesh::render {

namespace {

constexpr double kPi = 3.14159265358979323846;
double rad(double deg) { return deg * kPi / 180; }

struct ViewAngles {
  StandardView view;
  std::string_view name;
  double azimuth, elevation;
};

// Superior and inferior keep anterior up: the superior view comes from behind the head (azimuth
// 180), the inferior one from in front (azimuth 0), as 3D Slicer shows them.
constexpr std::array<ViewAngles, 7> kViews{{
    {StandardView::anterior, "anterior", 0, 0},
    {StandardView::posterior, "posterior", 180, 0},
    {StandardView::left, "left", 90, 0},
    {StandardView::right, "right", -90, 0},
    {StandardView::superior, "superior", 180, 90},
    {StandardView::inferior, "inferior", 0, -90},
    {StandardView::iso, "iso", 45, 30},
}};

}  // namespace

std::string_view view_name(StandardView view) {
  for (const auto& v : kViews)
    if (v.view == view) return v.name;
  return "?";
}

std::optional<StandardView> parse_view(std::string_view name) {
  for (const auto& v : kViews)
    if (v.name == name) return v.view;
  return std::nullopt;
}

void Bounds::add(Vec3d p) {
  if (empty()) {
    min = max = p;
    return;
  }
  min = {std::min(min.x, p.x), std::min(min.y, p.y), std::min(min.z, p.z)};
  max = {std::max(max.x, p.x), std::max(max.y, p.y), std::max(max.z, p.z)};
}

void Bounds::merge(const Bounds& b) {
  if (b.empty()) return;
  add(b.min);
  add(b.max);
}

Bounds mesh_bounds(const TriMesh& mesh) {
  Bounds b;
  if (mesh.positions.empty()) return b;
  Vec3f lo = mesh.positions[0], hi = lo;
  for (const Vec3f& p : mesh.positions) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  b.min = to_double(lo);
  b.max = to_double(hi);
  return b;
}

Bounds transformed_bounds(const Bounds& local, const Transform& transform) {
  if (local.empty()) return local;
  Bounds out;
  for (int c = 0; c < 8; ++c) {
    const Vec3d p{c & 1 ? local.max.x : local.min.x, c & 2 ? local.max.y : local.min.y,
                  c & 4 ? local.max.z : local.min.z};
    out.add(transform_point(transform, p));
  }
  return out;
}

Bounds scene_bounds(const Scene& scene, bool all) {
  Bounds b;
  for (const Part& p : scene.parts) {
    if (!all && !p.visible) continue;
    b.merge(transformed_bounds(mesh_bounds(p.mesh), p.transform));
  }
  return b;
}

CameraFrame camera_frame(const Camera& camera) {
  const double az = rad(camera.azimuth_deg);
  const double el = rad(std::clamp(camera.elevation_deg, -90.0, 90.0));
  const Vec3d to_eye{std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el)};
  CameraFrame f;
  f.forward = -1.0 * to_eye;
  f.right = {std::cos(az), std::sin(az), 0};
  f.up = cross(f.right, f.forward);
  f.eye = camera.target + camera.distance * to_eye;
  return f;
}

void set_view(Camera& camera, StandardView view) {
  for (const auto& v : kViews) {
    if (v.view != view) continue;
    camera.azimuth_deg = v.azimuth;
    camera.elevation_deg = v.elevation;
  }
}

void fit(Camera& camera, const Bounds& bounds, double aspect, double margin) {
  if (bounds.empty()) return;
  const CameraFrame f = camera_frame(camera);
  const Vec3d c = bounds.center();
  const double tan_v = std::tan(rad(camera.fov_y_deg) / 2) / margin;
  const double tan_h = tan_v * aspect;
  double distance = 0;
  for (int i = 0; i < 8; ++i) {
    const Vec3d p{i & 1 ? bounds.max.x : bounds.min.x, i & 2 ? bounds.max.y : bounds.min.y,
                  i & 4 ? bounds.max.z : bounds.min.z};
    const Vec3d q = p - c;
    const double x = std::abs(dot(q, f.right)), y = std::abs(dot(q, f.up));
    const double z = -dot(q, f.forward);  // towards the eye
    distance = std::max({distance, z + x / tan_h, z + y / tan_v});
  }
  camera.target = c;
  camera.distance = std::max(distance, 1e-3);
}

Camera standard_camera(const Scene& scene, StandardView view, double aspect) {
  Camera camera;
  set_view(camera, view);
  fit(camera, scene_bounds(scene), aspect);
  return camera;
}

void orbit(Camera& camera, double d_azimuth_deg, double d_elevation_deg) {
  camera.azimuth_deg = std::remainder(camera.azimuth_deg + d_azimuth_deg, 360.0);
  camera.elevation_deg = std::clamp(camera.elevation_deg + d_elevation_deg, -90.0, 90.0);
}

void pan(Camera& camera, double dx_pixels, double dy_pixels, int viewport_height) {
  if (viewport_height <= 0) return;
  const CameraFrame f = camera_frame(camera);
  const double mm_per_pixel =
      2 * camera.distance * std::tan(rad(camera.fov_y_deg) / 2) / viewport_height;
  camera.target = camera.target - (dx_pixels * mm_per_pixel) * f.right +
                  (dy_pixels * mm_per_pixel) * f.up;
}

void zoom(Camera& camera, double factor) {
  if (factor > 0 && std::isfinite(factor)) camera.distance = std::max(camera.distance / factor, 1e-3);
}

Mat4 view_matrix(const Camera& camera) {
  const CameraFrame f = camera_frame(camera);
  return look_along(f.eye, f.forward, f.up);
}

Mat4 projection_matrix(const Camera& camera, double aspect, double near, double far) {
  return perspective(rad(camera.fov_y_deg), aspect, near, far);
}

ClipRange clip_range(const Camera& camera, const Bounds& bounds) {
  ClipRange r;
  if (bounds.empty()) {
    r.near = camera.distance * 0.01;
    r.far = camera.distance * 100;
    return r;
  }
  const CameraFrame f = camera_frame(camera);
  const double radius = std::max(bounds.diagonal() / 2, 1e-3) * 1.02;
  const double centre = dot(bounds.center() - f.eye, f.forward);
  r.far = centre + radius;
  r.near = centre - radius;
  // Near must be positive; when the eye is inside the scene, keep a depth range of at most
  // 1:10^4 so 24-bit depth still separates surfaces.
  r.far = std::max(r.far, 1e-2);
  r.near = std::max(r.near, r.far * 1e-4);
  return r;
}

Ray pixel_ray(const Camera& camera, int width, int height, double x, double y) {
  const CameraFrame f = camera_frame(camera);
  const double aspect = double(width) / std::max(height, 1);
  const double nx = 2 * x / std::max(width, 1) - 1, ny = 1 - 2 * y / std::max(height, 1);
  const double tan_v = std::tan(rad(camera.fov_y_deg) / 2);
  return {f.eye, normalized(f.forward + (nx * tan_v * aspect) * f.right + (ny * tan_v) * f.up)};
}

std::optional<Vec3d> project_to_pixel(const Camera& camera, int width, int height, Vec3d world) {
  const CameraFrame f = camera_frame(camera);
  const double aspect = double(width) / std::max(height, 1);
  const double tan_v = std::tan(rad(camera.fov_y_deg) / 2);
  const Vec3d q = world - f.eye;
  const double depth = dot(q, f.forward);
  if (depth <= 0) return std::nullopt;
  const double sx = dot(q, f.right) / (depth * tan_v * aspect);
  const double sy = dot(q, f.up) / (depth * tan_v);
  return Vec3d{(sx + 1) / 2 * width, (1 - sy) / 2 * height, depth};
}

}  // namespace segmesh::render
