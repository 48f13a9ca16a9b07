// The surface-relevant structure of one connected component read straight from its runs
// (components.hpp), for Marching Cubes without a voxel mask.
//
// A component is a list of runs per row of voxels. Inside/outside along a row changes only at run
// ends, so everything an extractor needs from a row is interval arithmetic on a few run lists:
//   - the cut x-edges of a row are the two ends of each of its runs;
//   - the cut y-edges (z-edges) are where the row and its neighbour at y + 1 (z + 1) differ, the
//     symmetric difference of two run lists;
//   - the non-trivial cells between four rows are where their column pattern changes along x, or
//     where it is mixed (some rows inside, some outside).
// Merging the run lists (run_merge.hpp) visits each run end once, so the cost of a row is its
// number of run ends (plus, for the cells and edges themselves, the size of the output), never its
// length: the interior of a large bone costs nothing, and there is no pass over the volume per
// part.
//
// The scan's domain is the component's bounding box grown by one grid point on every side (the
// margin that closes the surface), in local indices 0 .. dims - 1; grid() places it in the world.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/detail/run_merge.hpp"
#include "segmesh/grid.hpp"

namespace segmesh {

class RunScan {
 public:
  RunScan(const Grid& volume_grid, const Components& components, const Component& component);

  const std::array<int64_t, 3>& dims() const { return dims_; }
  // The volume's grid moved to the domain (grid point (0, 0, 0) is the box's corner minus one).
  const Grid& grid() const { return grid_; }

  // The runs of domain row (j, k), x ascending (empty for the margin rows).
  std::span<const VoxelRun> row(int64_t j, int64_t k) const {
    if (j < 1 || k < 1 || j > ny_in_ || k > nz_in_) return {};
    const size_t r = static_cast<size_t>((k - 1) * ny_in_ + (j - 1));
    return {runs_ + row_first_[r], runs_ + row_first_[r + 1]};
  }
  // Local x of a run's first voxel and one past its last.
  int64_t begin_of(const VoxelRun& r) const { return r.x_begin - x0_; }
  int64_t end_of(const VoxelRun& r) const { return r.x_end - x0_; }

  // Calls visit(s, t, state) for consecutive intervals [s, t) covering [0, dims[0]) on which the
  // inside/outside state of the N rows is constant; bit n of state is row n's (run_merge.hpp).
  template <size_t N, class Visit>
  void segments(const std::array<std::span<const VoxelRun>, N>& rows, Visit&& visit) const {
    merge_runs<RowBits>(dims_[0], x0_, rows, [&](int64_t s, int64_t t, const RowBits& state) {
      visit(s, t, state.bits);
    });
  }

  // Calls visit(i) for every cut edge along `axis` starting at grid point (i, j, k), i ascending.
  template <class Visit>
  void row_edges(int axis, int64_t j, int64_t k, Visit&& visit) const {
    const auto a = row(j, k);
    if (axis == 0) {
      for (const VoxelRun& r : a) {
        visit(begin_of(r) - 1);
        visit(end_of(r) - 1);
      }
      return;
    }
    const auto b = axis == 1 ? row(j + 1, k) : row(j, k + 1);
    if (a.empty() && b.empty()) return;
    segments<2>({a, b}, [&](int64_t s, int64_t t, unsigned state) {
      if (state == 1 || state == 2) {
        for (int64_t i = s; i < t; ++i) visit(i);
      }
    });
  }

  // The number of edges row_edges visits, from the run ends alone.
  int64_t row_edge_count(int axis, int64_t j, int64_t k) const {
    const auto a = row(j, k);
    if (axis == 0) return 2 * static_cast<int64_t>(a.size());
    const auto b = axis == 1 ? row(j + 1, k) : row(j, k + 1);
    if (a.empty() || b.empty()) return length(a) + length(b);
    int64_t n = 0;
    segments<2>({a, b}, [&](int64_t s, int64_t t, unsigned state) {
      if (state == 1 || state == 2) n += t - s;
    });
    return n;
  }

  // Calls visit(i, case) for every non-trivial cell of row j of slab k (between planes k and
  // k + 1), i ascending; the case has bit c set when corner c (marching_cubes_table.hpp numbering)
  // is inside.
  template <class Visit>
  void cells(int64_t j, int64_t k, Visit&& visit) const {
    cell_spans(j, k, [&](int64_t first, int64_t last, int repeated, int boundary) {
      if (repeated != 0 && repeated != 255) {
        for (int64_t i = first; i < last; ++i) visit(i, repeated);
      }
      if (boundary != 0 && boundary != 255) visit(last, boundary);
    });
  }

  // The sum of weight(case) over the cells `cells` visits, computed per interval of equal cases
  // (weight(0) and weight(255), the trivial cases, must be 0).
  template <class Weight>
  int64_t cell_sum(int64_t j, int64_t k, Weight&& weight) const {
    int64_t sum = 0;
    cell_spans(j, k, [&](int64_t first, int64_t last, int repeated, int boundary) {
      sum += (last - first) * weight(repeated) + weight(boundary);
    });
    return sum;
  }

 private:
  static int64_t length(std::span<const VoxelRun> runs) {
    int64_t n = 0;
    for (const VoxelRun& r : runs) n += r.x_end - r.x_begin;
    return n;
  }

  // Cells of row j of slab k as spans: cells [first, last) all have case `repeated` (the column
  // pattern of the interval on both faces) and cell `last` has case `boundary` (the pattern
  // changes across it).
  template <class Span>
  void cell_spans(int64_t j, int64_t k, Span&& span) const {
    const std::array<std::span<const VoxelRun>, 4> rows{row(j, k), row(j + 1, k), row(j, k + 1),
                                                        row(j + 1, k + 1)};
    if (rows[0].empty() && rows[1].empty() && rows[2].empty() && rows[3].empty()) return;
    // Row n's state is corner bit 0, 2, 4 or 6 of a cell's left face (y = n & 1, z = n >> 1).
    static constexpr std::array<uint8_t, 16> kFace = [] {
      std::array<uint8_t, 16> f{};
      for (unsigned s = 0; s < 16; ++s) {
        f[s] = static_cast<uint8_t>((s & 1) | (s >> 1 & 1) << 2 | (s >> 2 & 1) << 4 | (s >> 3 & 1) << 6);
      }
      return f;
    }();
    int64_t first = 0;
    int face = -1;  // the previous interval's face pattern
    segments<4>(rows, [&](int64_t s, int64_t, unsigned state) {
      const int next = kFace[state];
      if (face >= 0) span(first, s - 1, face | face << 1, face | next << 1);
      first = s;
      face = next;
    });
    // The last interval reaches the margin, which is outside: nothing after it.
  }

  std::array<int64_t, 3> dims_{};
  Grid grid_;
  int64_t x0_ = 0;  // global x of local x = 0
  int64_t ny_in_ = 0, nz_in_ = 0;
  const VoxelRun* runs_ = nullptr;
  std::vector<uint32_t> row_first_;  // runs of box row r: [row_first_[r], row_first_[r + 1])
};

}  // namespace segmesh
