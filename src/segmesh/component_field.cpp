#include "segmesh/component_field.hpp"

#include <cmath>
#include <limits>

namespace segmesh {

namespace {

constexpr float kLargeValue = 1e30f;

}  // namespace

Grid component_grid(const Grid& grid, const Component& c, FieldMargin m) {
  return grid.crop({c.first[0] - m[0], c.first[1] - m[1], c.first[2] - m[2]},
                   {c.last[0] - c.first[0] + 1 + 2 * m[0], c.last[1] - c.first[1] + 1 + 2 * m[1],
                    c.last[2] - c.first[2] + 1 + 2 * m[2]});
}

Volume<uint8_t> component_mask(const Grid& grid, const Components& components,
                               const Component& component, FieldMargin margin) {
  Volume<uint8_t> mask;
  mask.grid = component_grid(grid, component, margin);
  mask.voxels.assign(mask.grid.voxel_count(), 0);
  const int64_t x0 = component.first[0] - margin[0], y0 = component.first[1] - margin[1],
                z0 = component.first[2] - margin[2];
  for (const VoxelRun& run : components.runs_of(component)) {
    uint8_t* row = &mask.at(run.x_begin - x0, run.y - y0, run.z - z0);
    std::fill(row, row + (run.x_end - run.x_begin), uint8_t{1});
  }
  return mask;
}

template <class T>
Volume<float> component_values(const Volume<T>& volume, const Components& components,
                               const Component& component, double iso, float background,
                               FieldMargin margin) {
  Volume<float> field;
  field.grid = component_grid(volume.grid, component, margin);
  field.voxels.assign(field.grid.voxel_count(), background);
  const float below = std::nextafter(static_cast<float>(iso), -std::numeric_limits<float>::infinity());
  const auto& d = volume.grid.dims;
  const int64_t x0 = component.first[0] - margin[0], y0 = component.first[1] - margin[1],
                z0 = component.first[2] - margin[2];
  const auto& fd = field.grid.dims;
  // Copy the volume's values inside its bounds, everything at or above iso lowered first ...
  for (int64_t k = std::max<int64_t>(z0, 0); k < std::min(z0 + fd[2], d[2]); ++k) {
    for (int64_t j = std::max<int64_t>(y0, 0); j < std::min(y0 + fd[1], d[1]); ++j) {
      for (int64_t i = std::max<int64_t>(x0, 0); i < std::min(x0 + fd[0], d[0]); ++i) {
        const float v = static_cast<float>(volume.at(i, j, k));
        field.at(i - x0, j - y0, k - z0) = (v >= iso) ? below : (std::isfinite(v) ? v : background);
      }
    }
  }
  // ... then this component's own voxels restored.
  for (const VoxelRun& run : components.runs_of(component)) {
    for (int32_t x = run.x_begin; x < run.x_end; ++x) {
      // +inf is inside; a large finite value keeps gradients and interpolation finite.
      field.at(x - x0, run.y - y0, run.z - z0) =
          std::min(static_cast<float>(volume.at(x, run.y, run.z)), kLargeValue);
    }
  }
  return field;
}

template Volume<float> component_values(const Volume<uint8_t>&, const Components&, const Component&,
                                        double, float, FieldMargin);
template Volume<float> component_values(const Volume<int16_t>&, const Components&, const Component&,
                                        double, float, FieldMargin);
template Volume<float> component_values(const Volume<uint16_t>&, const Components&, const Component&,
                                        double, float, FieldMargin);
template Volume<float> component_values(const Volume<int32_t>&, const Components&, const Component&,
                                        double, float, FieldMargin);
template Volume<float> component_values(const Volume<float>&, const Components&, const Component&,
                                        double, float, FieldMargin);

}  // namespace segmesh
