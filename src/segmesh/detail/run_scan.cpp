#include "segmesh/detail/run_scan.hpp"

#include <limits>

#include "segmesh/error.hpp"

namespace segmesh {

RunScan::RunScan(const Grid& volume_grid, const Components& components, const Component& component)
    : x0_(component.first[0] - 1),
      ny_in_(component.last[1] - component.first[1] + 1),
      nz_in_(component.last[2] - component.first[2] + 1) {
  for (int a = 0; a < 3; ++a) dims_[a] = component.last[a] - component.first[a] + 3;
  grid_ = volume_grid.crop({component.first[0] - 1, component.first[1] - 1, component.first[2] - 1},
                           dims_);
  const auto runs = components.runs_of(component);
  if (runs.size() > std::numeric_limits<uint32_t>::max()) {
    throw Error("marching cubes: a part has more than 4 billion runs of voxels");
  }
  runs_ = runs.data();
  // The runs are in (z, y, x) order: count them per box row, then prefix sums.
  row_first_.assign(static_cast<size_t>(ny_in_ * nz_in_) + 1, 0);
  const int64_t y0 = component.first[1], z0 = component.first[2];
  for (const VoxelRun& r : runs) ++row_first_[static_cast<size_t>((r.z - z0) * ny_in_ + (r.y - y0)) + 1];
  for (size_t r = 1; r < row_first_.size(); ++r) row_first_[r] += row_first_[r - 1];
}

}  // namespace segmesh
