#include "segmesh/detail/material_rows.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

#include "segmesh/error.hpp"

namespace segmesh {

MaterialRows::MaterialRows(const Grid& volume_grid, const Components& components,
                           std::span<const size_t> parts) {
  std::array<int64_t, 3> first{}, last{};
  for (int a = 0; a < 3; ++a) {
    first[a] = std::numeric_limits<int64_t>::max();
    last[a] = std::numeric_limits<int64_t>::min();
  }
  size_t total = 0;
  for (size_t p : parts) {
    const Component& c = components.components[p];
    for (int a = 0; a < 3; ++a) {
      first[a] = std::min(first[a], c.first[a]);
      last[a] = std::max(last[a], c.last[a]);
    }
    total += c.run_count;
  }
  if (parts.empty()) {
    grid_ = volume_grid;
    return;
  }
  if (parts.size() >= std::numeric_limits<uint32_t>::max()) {
    throw Error("multi-label extraction: more than 4 billion parts");
  }
  for (int a = 0; a < 3; ++a) dims_[a] = last[a] - first[a] + 3;
  grid_ = volume_grid.crop({first[0] - 1, first[1] - 1, first[2] - 1}, dims_);
  const int64_t ny = dims_[1] - 2, nz = dims_[2] - 2;
  // A counting sort of every part's runs by row, then each row by x.
  row_first_.assign(static_cast<size_t>(ny * nz) + 1, 0);
  auto row_of = [&](const VoxelRun& r) {
    return static_cast<size_t>((r.z - first[2]) * ny + (r.y - first[1]));
  };
  for (size_t p : parts) {
    for (const VoxelRun& r : components.runs_of(components.components[p])) ++row_first_[row_of(r) + 1];
  }
  for (size_t r = 1; r < row_first_.size(); ++r) row_first_[r] += row_first_[r - 1];
  runs_.resize(total);
  std::vector<size_t> at(row_first_.begin(), row_first_.end() - 1);
  const int32_t x0 = static_cast<int32_t>(first[0] - 1);
  for (size_t p = 0; p < parts.size(); ++p) {
    for (const VoxelRun& r : components.runs_of(components.components[parts[p]])) {
      runs_[at[row_of(r)]++] = {r.x_begin - x0, r.x_end - x0, static_cast<uint32_t>(p + 1)};
    }
  }
  tbb::parallel_for(size_t{0}, row_first_.size() - 1, [&](size_t r) {
    const auto begin = runs_.begin() + static_cast<std::ptrdiff_t>(row_first_[r]);
    const auto end = runs_.begin() + static_cast<std::ptrdiff_t>(row_first_[r + 1]);
    if (end - begin > 1) {
      std::sort(begin, end,
                [](const MaterialRun& a, const MaterialRun& b) { return a.x_begin < b.x_begin; });
    }
  });
}

}  // namespace segmesh
