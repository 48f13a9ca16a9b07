// The parts of a label map as runs per row of voxels, each run tagged with its part's material
// (the part's index in the scene + 1; material 0, the background, is everything not in a run),
// for the multi-label extractor (multi_label_marching_cubes.hpp).
//
// What a row of cells needs from its four rows of voxels is where their materials change along
// x; merging the four run lists (run_merge.hpp) gives it in one visit of each run end, so the
// interior of a large bone costs nothing and no volume of materials is ever allocated (a uint16
// material per voxel would double the memory of a uint8 label map).
//
// The domain is the parts' common bounding box grown by one grid point on every side (the margin
// that closes every surface), in local indices 0 .. dims - 1; grid() places it in the world.
// Cost: O(runs) time and memory to build (a counting sort by row, then each row sorted by x).
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/detail/run_merge.hpp"
#include "segmesh/grid.hpp"

namespace segmesh {

struct MaterialRun {
  int32_t x_begin = 0, x_end = 0;  // local x of the first voxel and one past the last
  uint32_t material = 0;
};

class MaterialRows {
 public:
  // `parts[p]` indexes components.components; part p gets material p + 1.
  MaterialRows(const Grid& volume_grid, const Components& components,
               std::span<const size_t> parts);

  const std::array<int64_t, 3>& dims() const { return dims_; }
  const Grid& grid() const { return grid_; }
  bool empty() const { return runs_.empty(); }

  // The runs of local row (j, k), x ascending (empty for the margin rows).
  std::span<const MaterialRun> row(int64_t j, int64_t k) const {
    if (j < 1 || k < 1 || j > dims_[1] - 2 || k > dims_[2] - 2) return {};
    const size_t r = static_cast<size_t>((k - 1) * (dims_[1] - 2) + (j - 1));
    return {runs_.data() + row_first_[r], runs_.data() + row_first_[r + 1]};
  }

  // Calls visit(s, t, materials) for consecutive intervals [s, t) covering [0, dims[0]) on which
  // the materials of the N rows are constant; materials[n] is row n's (run_merge.hpp).
  template <size_t N, class Visit>
  void segments(const std::array<std::span<const MaterialRun>, N>& rows, Visit&& visit) const {
    merge_runs<RunValues<N, &MaterialRun::material>>(
        dims_[0], 0, rows,
        [&](int64_t s, int64_t t, const auto& state) { visit(s, t, state.value); });
  }

  // Calls visit(i, materials) for every cell of row j of slab k whose corners are not all one
  // material (and a few whose corners are, which the caller skips), i ascending (corner numbering
  // of marching_cubes_table.hpp): the stretches where the four rows do not change cost nothing.
  template <class Visit>
  void cells(int64_t j, int64_t k, Visit&& visit) const {
    const std::array<std::span<const MaterialRun>, 4> r{row(j, k), row(j + 1, k), row(j, k + 1),
                                                        row(j + 1, k + 1)};
    if (r[0].empty() && r[1].empty() && r[2].empty() && r[3].empty()) return;
    // Row n holds corners 2n (left face) and 2n + 1 (right face).
    std::array<uint32_t, 4> face{};
    int64_t first = -1;
    uint32_t m[8];
    auto emit = [&](int64_t i, const std::array<uint32_t, 4>& left,
                    const std::array<uint32_t, 4>& right) {
      for (int n = 0; n < 4; ++n) {
        m[2 * n] = left[n];
        m[2 * n + 1] = right[n];
      }
      visit(i, m);
    };
    segments<4>(r, [&](int64_t s, int64_t, const std::array<uint32_t, 4>& next) {
      if (first >= 0) {
        const bool uniform = face[0] == face[1] && face[1] == face[2] && face[2] == face[3];
        if (!uniform)
          for (int64_t i = first; i < s - 1; ++i) emit(i, face, face);
        emit(s - 1, face, next);  // the cell across the change (may be uniform in the end)
      }
      first = s;
      face = next;
    });
    // The last interval reaches the margin, where every row is background.
  }

 private:
  std::array<int64_t, 3> dims_{};
  Grid grid_;
  std::vector<MaterialRun> runs_;
  std::vector<size_t> row_first_;  // runs of inner row r: [row_first_[r], row_first_[r + 1])
};

}  // namespace segmesh
