// Row trimming for the extractors, after VTK's flying edges: one pass over every row of voxels
// records where the inside/outside state changes along x (the first and last sign-changing x-edge)
// and the states at both ends. Cells and edges away from those ranges, where the rows involved are
// constant and equal, can hold no surface and are skipped without being looked at. Label maps are
// mostly background, and a part's crop mostly interior or exterior, so most rows are skipped or
// trimmed to a few voxels.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

#include "segmesh/progress.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

// value >= iso, decided in the voxel type: integers compare against ceil(iso), so the test is one
// integer comparison; floating point compares in double (NaN is outside).
template <class T>
class InsideTest {
 public:
  explicit InsideTest(double iso) : iso_(iso) {
    if constexpr (std::is_integral_v<T>) {
      const double c = std::ceil(iso);
      threshold_ = c > 9.0e18 ? std::numeric_limits<int64_t>::max()
                 : c < -9.0e18 ? std::numeric_limits<int64_t>::min()
                               : static_cast<int64_t>(c);
    }
  }
  bool operator()(T v) const {
    if constexpr (std::is_integral_v<T>) {
      return static_cast<int64_t>(v) >= threshold_;
    } else {
      return static_cast<double>(v) >= iso_;
    }
  }

 private:
  double iso_;
  int64_t threshold_ = 0;
};

// Grid points [lo, hi) along x.
struct GridRange {
  int64_t lo = 0, hi = 0;
  bool empty() const { return lo >= hi; }
};

struct RowTrim {
  int32_t first_cut = 0;  // sign-changing x-edges lie in [first_cut, end_cut); none: empty
  int32_t end_cut = 0;
  bool inside_first = false;  // state at x = 0
  bool inside_last = false;   // state at x = nx - 1
};

// Grid points where any of `rows` may change state or differ from one another.
template <class... Rows>
GridRange rows_range(int64_t nx, const RowTrim& a, const Rows&... rest) {
  int64_t lo = a.first_cut < a.end_cut ? a.first_cut : nx;
  int64_t hi = a.first_cut < a.end_cut ? a.end_cut + 1 : 0;
  bool same_first = true, same_last = true;
  auto add = [&](const RowTrim& r) {
    if (r.first_cut < r.end_cut) {
      lo = std::min<int64_t>(lo, r.first_cut);
      hi = std::max<int64_t>(hi, r.end_cut + 1);
    }
    same_first = same_first && r.inside_first == a.inside_first;
    same_last = same_last && r.inside_last == a.inside_last;
  };
  (add(rest), ...);
  if (!same_first) lo = 0;
  if (!same_last) hi = nx;
  return {std::max<int64_t>(lo, 0), std::min<int64_t>(hi, nx)};
}

inline GridRange pair_range(const RowTrim& a, const RowTrim& b, int64_t nx) {
  return rows_range(nx, a, b);
}
inline GridRange quad_range(const RowTrim& a, const RowTrim& b, const RowTrim& c, const RowTrim& d,
                            int64_t nx) {
  return rows_range(nx, a, b, c, d);
}

// One RowTrim per row (y, z), row index z * ny + y. Parallel over rows.
template <class T>
std::vector<RowTrim> trim_rows(const Volume<T>& f, const InsideTest<T>& inside, Progress& progress) {
  const int64_t nx = f.grid.dims[0];
  const int64_t rows = f.grid.dims[1] * f.grid.dims[2];
  std::vector<RowTrim> out(static_cast<size_t>(rows));
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows, 512), [&](const auto& r) {
    throw_if_cancelled(progress);
    for (int64_t row = r.begin(); row < r.end(); ++row) {
      const T* v = f.voxels.data() + static_cast<size_t>(row * nx);
      RowTrim t;
      t.inside_first = inside(v[0]);
      t.inside_last = inside(v[nx - 1]);
      int64_t first = -1, last = -1;
      bool previous = t.inside_first;
      for (int64_t x = 1; x < nx; ++x) {
        const bool in = inside(v[x]);
        if (in != previous) {
          if (first < 0) first = x - 1;
          last = x - 1;
          previous = in;
        }
      }
      if (first >= 0) {
        t.first_cut = static_cast<int32_t>(first);
        t.end_cut = static_cast<int32_t>(last + 1);
      }
      out[static_cast<size_t>(row)] = t;
    }
  });
  return out;
}

// Scans one field with its row trims: per row, the sign-changing edges and the non-trivial cells,
// x ascending (the order both extractors number their output in).
template <class T>
class TrimmedScan {
 public:
  TrimmedScan(const Volume<T>& f, const InsideTest<T>& inside, Progress& progress)
      : f_(f), inside_(inside), rows_(trim_rows(f, inside, progress)),
        nx_(f.grid.dims[0]), ny_(f.grid.dims[1]), nz_(f.grid.dims[2]) {}

  // The cells [first, last) of row j of slab k (between planes k and k + 1) that may be
  // non-trivial.
  GridRange cell_range(int64_t j, int64_t k) const {
    const GridRange g = quad_range(trim(j, k), trim(j + 1, k), trim(j, k + 1), trim(j + 1, k + 1), nx_);
    if (g.empty()) return {};
    return {std::max<int64_t>(g.lo - 1, 0), std::min<int64_t>(g.hi, nx_ - 1)};
  }

  // Calls visit(i, case) for every non-trivial cell of row j of slab k, x ascending. The case
  // has bit c set when corner c (marching_cubes_table.hpp numbering) is inside; it is built by
  // sliding along x, the right face of one cell being the left face of the next.
  template <class Visit>
  void cells(int64_t j, int64_t k, Visit&& visit) const {
    const GridRange range = cell_range(j, k);
    if (range.empty()) return;
    const T* r00 = row(j, k);
    const T* r10 = row(j + 1, k);
    const T* r01 = row(j, k + 1);
    const T* r11 = row(j + 1, k + 1);
    auto face = [&](int64_t x) {  // corners 0, 2, 4, 6 of the cell starting at x
      return int(inside_(r00[x])) | int(inside_(r10[x])) << 2 | int(inside_(r01[x])) << 4 |
             int(inside_(r11[x])) << 6;
    };
    int left = face(range.lo);
    for (int64_t i = range.lo; i < range.hi; ++i) {
      const int right = face(i + 1);
      const int cs = left | right << 1;
      left = right;
      if (cs != 0 && cs != 255) visit(i, cs);
    }
  }

  // Calls visit(i) for every sign-changing edge along `axis` starting at grid point (i, j, k),
  // i ascending (Marching Cubes numbers its vertices row by row and axis by axis).
  template <class Visit>
  void row_edges(int axis, int64_t j, int64_t k, Visit&& visit) const {
    const RowTrim& r = trim(j, k);
    const T* a = row(j, k);
    if (axis == 0) {
      for (int64_t i = r.first_cut; i < r.end_cut; ++i) {
        if (inside_(a[i]) != inside_(a[i + 1])) visit(i);
      }
      return;
    }
    if (axis == 1 ? j + 1 >= ny_ : k + 1 >= nz_) return;
    const int64_t jb = axis == 1 ? j + 1 : j, kb = axis == 1 ? k : k + 1;
    const GridRange range = pair_range(r, trim(jb, kb), nx_);
    const T* b = row(jb, kb);
    for (int64_t i = range.lo; i < range.hi; ++i) {
      if (inside_(a[i]) != inside_(b[i])) visit(i);
    }
  }

  int64_t row_edge_count(int axis, int64_t j, int64_t k) const {
    int64_t n = 0;
    row_edges(axis, j, k, [&](int64_t) { ++n; });
    return n;
  }

  // The sum of weight(case) over the cells `cells` visits.
  template <class Weight>
  int64_t cell_sum(int64_t j, int64_t k, Weight&& weight) const {
    int64_t sum = 0;
    cells(j, k, [&](int64_t, int cs) { sum += weight(cs); });
    return sum;
  }

 private:
  const T* row(int64_t j, int64_t k) const {
    return f_.voxels.data() + static_cast<size_t>((k * ny_ + j) * nx_);
  }
  const RowTrim& trim(int64_t j, int64_t k) const { return rows_[static_cast<size_t>(k * ny_ + j)]; }

  const Volume<T>& f_;
  InsideTest<T> inside_;
  std::vector<RowTrim> rows_;
  int64_t nx_, ny_, nz_;
};

}  // namespace segmesh
