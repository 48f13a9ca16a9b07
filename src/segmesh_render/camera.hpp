// Camera: where the planning view looks from, as plain data, with the operations a viewer needs
// (orbit, pan, zoom, standard views, fit to the scene) and the matrices the renderer uses.
//
// The camera orbits a target point like a turntable around the patient's superior axis: world
// axes are LPS millimetres (x towards the patient's left, y posterior, z superior), the camera
// keeps the superior direction on the screen's vertical plane (no roll), and its elevation stops
// at the poles (looking straight down or up), where the azimuth still decides which way is up.
//
// Standard views (the eye's position, where it looks, what is up on the screen):
//   anterior   eye in front of the patient (-y), looks towards +y; superior up, patient's left
//              (+x) on the screen's right (as a surgeon facing the patient sees it)
//   posterior  eye behind (+y), looks towards -y; superior up, patient's right (-x) on the right
//   left       eye at the patient's left (+x), looks towards -x; superior up, posterior on the right
//   right      eye at the patient's right (-x), looks towards +x; superior up, anterior on the right
//   superior   eye above (+z), looks down (-z); anterior up, patient's right on the right
//   inferior   eye below (-z), looks up (+z); anterior up, patient's left on the right
//   iso        eye anterior, to the patient's left and above (azimuth 45, elevation 30): a
//              three-quarter view; for a right leg it shows the medial and anterior faces
#pragma once

#include <optional>
#include <string_view>

#include "segmesh/scene.hpp"
#include "segmesh/vec3.hpp"
#include "segmesh_render/mat4.hpp"

namespace segmesh::render {

enum class StandardView { anterior, posterior, left, right, superior, inferior, iso };

std::string_view view_name(StandardView view);
// "anterior", "posterior", "left", "right", "superior", "inferior", "iso"; nullopt otherwise.
std::optional<StandardView> parse_view(std::string_view name);

struct Camera {
  Vec3d target{0, 0, 0};     // the orbit centre, world mm
  double distance = 500;     // from the eye to the target, mm (> 0)
  // Around the superior (+z) axis, degrees: 0 puts the eye anterior (-y), 90 at the patient's
  // left (+x), 180 posterior, -90 at the right.
  double azimuth_deg = 0;
  // Above the axial plane, degrees, in [-90, 90]: 90 puts the eye superior, -90 inferior.
  double elevation_deg = 0;
  double fov_y_deg = 30;     // vertical field of view (perspective projection)
};

// The camera's frame in world coordinates: unit vectors; right = forward x up.
struct CameraFrame {
  Vec3d eye, forward, right, up;
};
CameraFrame camera_frame(const Camera& camera);

// An axis-aligned box in world mm; empty when min > max on any axis.
struct Bounds {
  Vec3d min{1, 1, 1}, max{-1, -1, -1};
  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
  Vec3d center() const { return 0.5 * (min + max); }
  double diagonal() const { return empty() ? 0 : norm(max - min); }
  void add(Vec3d p);
  void merge(const Bounds& b);
};

// The bounds of a mesh's positions (empty for an empty mesh).
Bounds mesh_bounds(const TriMesh& mesh);
// The bounds of `local` moved by `transform` (the box around the eight moved corners).
Bounds transformed_bounds(const Bounds& local, const Transform& transform);
// The bounds of the scene's parts with their transforms applied; only the visible ones (Part::
// visible) unless `all`. Empty when nothing is visible.
Bounds scene_bounds(const Scene& scene, bool all = false);

// Sets azimuth and elevation to the standard view's (target and distance stay).
void set_view(Camera& camera, StandardView view);

// Points the camera at the centre of `bounds` and sets the distance so that the whole box fits
// in a viewport of the given aspect (width / height), with `margin` (1.05: 5 % spare) around it,
// from the current direction. Does nothing for empty bounds.
void fit(Camera& camera, const Bounds& bounds, double aspect, double margin = 1.05);

// The standard view of the visible parts of `scene`, fitted to a viewport of `aspect`.
Camera standard_camera(const Scene& scene, StandardView view, double aspect);

// Mouse-style operations. orbit turns the eye around the target (degrees; elevation clamped);
// pan moves the target in the view plane by a number of pixels of a viewport `viewport_height`
// pixels high (the scene follows the mouse at the target's depth; x right, y down); zoom divides
// the distance by `factor` (> 1 moves closer).
void orbit(Camera& camera, double d_azimuth_deg, double d_elevation_deg);
void pan(Camera& camera, double dx_pixels, double dy_pixels, int viewport_height);
void zoom(Camera& camera, double factor);

// The matrices. near and far are distances along the view direction (the renderer chooses them
// from the scene's bounds: clip_range).
Mat4 view_matrix(const Camera& camera);
Mat4 projection_matrix(const Camera& camera, double aspect, double near, double far);

// Near and far planes that hold `bounds` (with a little slack) for this camera; sensible
// defaults when the bounds are empty. The eye may be inside the box.
struct ClipRange {
  double near = 1, far = 1000;
};
ClipRange clip_range(const Camera& camera, const Bounds& bounds);

// The ray through pixel (x, y) of a width x height viewport: x right, y down, (0, 0) the top-left
// pixel's corner, so pixel (i, j)'s centre is (i + 0.5, j + 0.5). `direction` is unit length.
struct Ray {
  Vec3d origin, direction;
};
Ray pixel_ray(const Camera& camera, int width, int height, double x, double y);

// Where a world point lands in a width x height viewport (same pixel convention as pixel_ray);
// nullopt when it is behind the eye.
std::optional<Vec3d> project_to_pixel(const Camera& camera, int width, int height, Vec3d world);

}  // namespace segmesh::render
