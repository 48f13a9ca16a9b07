// Grid: where a voxel array sits in the world.
//
// Index (i, j, k) maps to world millimetres as origin + direction * (spacing ⊙ (i, j, k)), the
// ITK / DICOM convention (LPS world axes). Voxel values sit at the grid points; a voxel's centre
// is its grid point. The direction's columns are the world directions of the i, j, k axes; they
// are orthonormal, and the determinant may be -1 (a mirrored grid), which flips the winding of
// anything built in index space.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "segmesh/vec3.hpp"

namespace segmesh {

struct Grid {
  std::array<int64_t, 3> dims{0, 0, 0};
  std::array<double, 3> spacing{1, 1, 1};  // mm, all > 0
  std::array<double, 3> origin{0, 0, 0};   // world position of voxel (0, 0, 0), mm
  Mat3d direction = identity3();           // row-major; column c is the world direction of axis c

  size_t voxel_count() const {
    return static_cast<size_t>(dims[0]) * static_cast<size_t>(dims[1]) *
           static_cast<size_t>(dims[2]);
  }
  double voxel_volume() const { return spacing[0] * spacing[1] * spacing[2]; }
  bool mirrored() const { return determinant(direction) < 0; }

  // Linear index of (i, j, k), x fastest.
  size_t index(int64_t i, int64_t j, int64_t k) const {
    return static_cast<size_t>((k * dims[1] + j) * dims[0] + i);
  }

  Vec3d to_world(Vec3d ijk) const {
    const Vec3d scaled{ijk.x * spacing[0], ijk.y * spacing[1], ijk.z * spacing[2]};
    const Vec3d d = direction * scaled;
    return {origin[0] + d.x, origin[1] + d.y, origin[2] + d.z};
  }

  // Maps a gradient taken in index space (per-voxel differences) to a world-space gradient:
  // direction * (g / spacing). Normals built from it are correct on anisotropic grids.
  Vec3d gradient_to_world(Vec3d g_index) const {
    return direction * Vec3d{g_index.x / spacing[0], g_index.y / spacing[1], g_index.z / spacing[2]};
  }

  // The sub-grid that starts at index `first` (which may be negative: padding) with `dims`.
  Grid crop(std::array<int64_t, 3> first, std::array<int64_t, 3> crop_dims) const {
    Grid g = *this;
    const Vec3d o = to_world({double(first[0]), double(first[1]), double(first[2])});
    g.origin = {o.x, o.y, o.z};
    g.dims = crop_dims;
    return g;
  }
};

}  // namespace segmesh
