// The ambient occlusion scene of issue 40: a bone block, a small fragment resting on it (the
// contact crease) and a screw entering it (the entry crease), as a label map meshed by the
// pipeline, with the pixel measures the AO test and bench/ao_creases.cpp share: how much darker
// every object pixel is with occlusion on than off, and the pixels of the block's flat, open top.
//
// Geometry (world mm, voxels of 0.5 mm, identity direction, origin 0):
// - bone (label 1): the block x 5..95, y 5..55, z 5..25; its top (z = 25.25 after meshing, the
//   voxel faces' midpoint) is the flat open surface, widest beyond the screw (x 55..95);
// - fragment (label 1, its own component): an ellipsoid with semi-axes 8, 6, 4 about
//   (20, 25, 28.5), cut flat at z = 26: it rests on the top across a one-voxel gap (a segmented
//   fracture fragment), so its wall meets the top at an acute angle all round;
// - screw (label 2): a 3.5 mm shaft along z at (45, 30) from z = 10 up to a 6 mm head at
//   z 30..32.5, so 5 mm of shaft stand above the top; it replaces the bone it overlaps.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/renderer.hpp"
#include "support/pictures.hpp"

namespace segmesh::test {

struct CreaseGeometry {
  double spacing = 0.5;
  Vec3d block_min{5, 5, 5}, block_max{95, 55, 25};  // mm, voxel centres
  double top = 25;                                   // block_max.z
  Vec3d fragment_centre{20, 25, 28.5};
  Vec3d fragment_axes{8, 6, 4};
  double fragment_cut = 26;                   // the fragment's flat underside
  Vec3d screw_axis{45, 30, 0};                // x, y of the axis
  double shaft_radius = 1.75, head_radius = 3;
  double shaft_bottom = 10, head_bottom = 30, head_top = 32.5;
};

inline Image crease_image(const CreaseGeometry& g = {}) {
  Volume<uint8_t> v;
  v.grid.dims = {200, 120, 80};
  v.grid.spacing = {g.spacing, g.spacing, g.spacing};
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 0; k < v.grid.dims[2]; ++k)
    for (int64_t j = 0; j < v.grid.dims[1]; ++j)
      for (int64_t i = 0; i < v.grid.dims[0]; ++i) {
        const double x = i * g.spacing, y = j * g.spacing, z = k * g.spacing;
        uint8_t label = 0;
        if (x >= g.block_min.x && x <= g.block_max.x && y >= g.block_min.y && y <= g.block_max.y &&
            z >= g.block_min.z && z <= g.top) {
          label = 1;
        }
        const double ex = (x - g.fragment_centre.x) / g.fragment_axes.x,
                     ey = (y - g.fragment_centre.y) / g.fragment_axes.y,
                     ez = (z - g.fragment_centre.z) / g.fragment_axes.z;
        if (z >= g.fragment_cut && ex * ex + ey * ey + ez * ez <= 1) label = 1;
        const double r = std::hypot(x - g.screw_axis.x, y - g.screw_axis.y);
        if ((z >= g.shaft_bottom && z < g.head_bottom && r <= g.shaft_radius) ||
            (z >= g.head_bottom && z <= g.head_top && r <= g.head_radius)) {
          label = 2;
        }
        v.at(i, j, k) = label;
      }
  Image image;
  image.path = "crease scene";
  image.voxel_type = "uint8";
  image.volume = std::move(v);
  return image;
}

// The scene as `segmesh render` meshes a volume: the pipeline's default options.
inline Scene crease_scene(const CreaseGeometry& g = {}) {
  return build_scene(crease_image(g), MeshingOptions{});
}

// The camera of the measurement: `segmesh render`'s iso view (anterior, left, above) of the
// whole scene.
inline render::Camera crease_camera(const Scene& scene, int w, int h) {
  return render::standard_camera(scene, render::StandardView::iso, double(w) / h);
}

// How much darker each pixel is with occlusion than without (luminance, 0..255; negative where it
// got brighter), for the pixels listed.
inline std::vector<double> darkening(const render::RgbaImage& on, const render::RgbaImage& off,
                                     const std::vector<int>& pixels) {
  std::vector<double> d;
  d.reserve(pixels.size());
  for (int p : pixels) d.push_back(luminance(&off.rgba[4 * size_t(p)]) - luminance(&on.rgba[4 * size_t(p)]));
  return d;
}

// The q-quantile (0..1) of `values` (nearest rank); 0 for none.
inline double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

// Pixels of a w x h view whose id is a part (the object pixels).
inline std::vector<int> object_pixels(const std::vector<int32_t>& ids) {
  std::vector<int> out;
  for (size_t i = 0; i < ids.size(); ++i)
    if (ids[i] >= 0) out.push_back(int(i));
  return out;
}

// Where pixel (x, y)'s ray meets the plane of the block's top (nullopt behind the eye or parallel).
inline std::optional<Vec3d> on_top_plane(const render::Camera& camera, int w, int h, int x, int y,
                                         const CreaseGeometry& g = {}) {
  const double plane = g.top + 0.5 * g.spacing;
  const render::Ray ray = render::pixel_ray(camera, w, h, x + 0.5, y + 0.5);
  if (std::abs(ray.direction.z) < 1e-9) return std::nullopt;
  const double t = (plane - ray.origin.z) / ray.direction.z;
  if (t <= 0) return std::nullopt;
  return ray.origin + t * ray.direction;
}

// How far outside the fragment's widest outline a point of the top plane is, mm (roughly: the
// ellipse grown by d passes through it); negative inside.
inline double outside_fragment(Vec3d p, const CreaseGeometry& g = {}) {
  const double ex = (p.x - g.fragment_centre.x) / g.fragment_axes.x,
               ey = (p.y - g.fragment_centre.y) / g.fragment_axes.y;
  return (std::sqrt(ex * ex + ey * ey) - 1) * std::min(g.fragment_axes.x, g.fragment_axes.y);
}

// How far from the screw's shaft a point of the top plane is, mm.
inline double outside_shaft(Vec3d p, const CreaseGeometry& g = {}) {
  return std::hypot(p.x - g.screw_axis.x, p.y - g.screw_axis.y) - g.shaft_radius;
}

// Pixels of part `block` whose ray meets the top plane at a point that `keep` accepts.
inline std::vector<int> top_pixels_where(const std::vector<int32_t>& ids, const render::Camera& camera,
                                         int w, int h, int block,
                                         const std::function<bool(Vec3d)>& keep,
                                         const CreaseGeometry& g = {}) {
  std::vector<int> out;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (ids[size_t(y) * w + x] != block) continue;
      const std::optional<Vec3d> p = on_top_plane(camera, w, h, x, y, g);
      if (p && keep(*p)) out.push_back(y * w + x);
    }
  return out;
}

// Pixels that show the block's top at least `clearance` mm from the fragment, the screw and the
// block's edges (the flat, open surface), found by casting each pixel's ray onto the top plane.
// `block` is the block's part index.
inline std::vector<int> open_top_pixels(const std::vector<int32_t>& ids, const render::Camera& camera,
                                        int w, int h, int block, double clearance,
                                        const CreaseGeometry& g = {}) {
  return top_pixels_where(ids, camera, w, h, block, [&](Vec3d p) {
    return p.x >= g.block_min.x + clearance && p.x <= g.block_max.x - clearance &&
           p.y >= g.block_min.y + clearance && p.y <= g.block_max.y - clearance &&
           std::hypot(p.x - g.screw_axis.x, p.y - g.screw_axis.y) >= g.head_radius + clearance &&
           outside_fragment(p, g) >= clearance;
  }, g);
}

}  // namespace segmesh::test
