#include "segmesh/scene.hpp"

#include <tbb/parallel_for.h>

#include <cmath>

#include "segmesh/smoothing.hpp"

namespace segmesh {

namespace {

// Distinct, fairly light colours for labels without a role colour: golden-angle hues.
Rgb palette_color(int32_t label) {
  const double hue = std::fmod(0.61803398875 * static_cast<double>(label), 1.0) * 6.0;
  const double s = 0.55, v = 0.85;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = v, g = t, b = p;
  switch (sector) {
    case 0: r = v, g = t, b = p; break;
    case 1: r = q, g = v, b = p; break;
    case 2: r = p, g = v, b = t; break;
    case 3: r = p, g = q, b = v; break;
    case 4: r = t, g = p, b = v; break;
    default: r = v, g = p, b = q; break;
  }
  return {float(r), float(g), float(b)};
}

}  // namespace

Material default_material(Role role, int32_t label, std::optional<Rgb> color) {
  switch (role) {
    case Role::bone:
      return {color.value_or(Rgb{0.95f, 0.93f, 0.88f}), 0.0f, 0.6f};
    case Role::implant:
      return {color.value_or(Rgb{0.8f, 0.05f, 0.05f}), 1.0f, 0.7f};
    case Role::other:
      break;
  }
  return {color.value_or(palette_color(label)), 0.0f, 0.6f};
}

void set_part_shells(Scene& scene, ShellOrigins* origin) {
  std::vector<TriMesh> shells = part_shells(*scene.surface, origin);
  tbb::parallel_for(size_t{0}, scene.parts.size(), [&](size_t p) {
    compute_vertex_normals(shells[p]);
    scene.parts[p].mesh = std::move(shells[p]);
  });
}

}  // namespace segmesh
