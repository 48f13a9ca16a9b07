// What the renderer tests share: the phantom scene, a headless context, and pixel measures.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_render/camera.hpp"
#include "segmesh_render/headless_context.hpp"
#include "segmesh_render/renderer.hpp"
#include "support/pictures.hpp"  // luminance and the pixel classes

namespace segmesh::test {

// The phantom at 256 x 256 x 102 voxels of 0.394 x 0.394 x 4 mm (the anatomy at full size, s = 1),
// meshed by the pipeline with the default options (Marching Cubes, windowed sinc smoothing) or the
// ones given. Parts: 3 bone (two tibia fragments, fibula), then the plate and six screws.
inline Scene phantom_scene(MeshingOptions options = {}) {
  Image image;
  image.path = "phantom";
  image.volume = make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4}});
  return build_scene(image, options);
}

// The part's centroid (mean of its vertices), world mm.
inline Vec3d centroid(const Part& part) {
  Vec3d sum;
  for (const Vec3f& p : part.mesh.positions) sum = sum + to_double(p);
  return (1.0 / double(std::max<size_t>(part.mesh.positions.size(), 1))) * sum;
}

// Indices of the parts that satisfy `keep`.
inline std::vector<int> parts_where(const Scene& scene, const std::function<bool(const Part&)>& keep) {
  std::vector<int> out;
  for (size_t i = 0; i < scene.parts.size(); ++i)
    if (keep(scene.parts[i])) out.push_back(int(i));
  return out;
}

struct PhantomParts {
  int fibula = -1, proximal_tibia = -1, distal_tibia = -1, plate = -1;
  std::vector<int> screws, bones, implants;
};

inline PhantomParts phantom_parts(const Scene& scene) {
  PhantomParts p;
  p.bones = parts_where(scene, [](const Part& x) { return x.role == Role::bone; });
  p.implants = parts_where(scene, [](const Part& x) { return x.role == Role::implant; });
  for (int b : p.bones) {
    const Vec3d c = centroid(scene.parts[b]);
    if (c.x < -10) p.fibula = b;
    else if (c.z > -50) p.proximal_tibia = b;
    else p.distal_tibia = b;
  }
  // The plate is the largest implant component (the pipeline orders a label's parts by size).
  p.plate = p.implants.empty() ? -1 : p.implants.front();
  for (size_t i = 1; i < p.implants.size(); ++i) p.screws.push_back(p.implants[i]);
  return p;
}


// Pixels whose id is in `ids` and whose 8 neighbours have the same id (edges mix colours).
inline std::vector<int> interior_pixels(const std::vector<int32_t>& id_image, int w, int h,
                                        const std::function<bool(int32_t)>& wanted) {
  std::vector<int> out;
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const int32_t id = id_image[size_t(y) * w + x];
      if (!wanted(id)) continue;
      bool inside = true;
      for (int dy = -1; dy <= 1 && inside; ++dy)
        for (int dx = -1; dx <= 1 && inside; ++dx) inside = id_image[size_t(y + dy) * w + x + dx] == id;
      if (inside) out.push_back(y * w + x);
    }
  return out;
}

inline bool contains(const std::vector<int>& v, int32_t x) {
  return std::find(v.begin(), v.end(), x) != v.end();
}

// A headless context and a renderer for one test.
struct RenderFixture : ::testing::Test {
  std::unique_ptr<render::HeadlessContext> context;
  std::unique_ptr<render::Renderer> renderer;
  void SetUp() override {
    context = std::make_unique<render::HeadlessContext>();
    renderer = std::make_unique<render::Renderer>();
  }
  void TearDown() override {
    renderer.reset();
    context.reset();
  }
};

}  // namespace segmesh::test
