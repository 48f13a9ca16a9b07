#include "segmesh/components.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace segmesh {

namespace {

struct RunLabel {
  VoxelRun run;
  int32_t label;
};

// Finds the runs of every row; `label_of(value)` gives a voxel's label (0 = not wanted).
template <class T, class LabelOf>
std::vector<RunLabel> find_runs(const Volume<T>& volume, LabelOf label_of, Progress& progress,
                                std::vector<size_t>& row_first) {
  const auto& d = volume.grid.dims;
  const int64_t rows = d[1] * d[2];
  // Rows are scanned twice (count, then fill) so the runs land in one array without locks.
  auto scan_row = [&](int64_t row, auto&& emit) {
    const T* v = volume.voxels.data() + static_cast<size_t>(row) * d[0];
    T last_value = v[0];
    int32_t last_label = label_of(v[0]);
    int32_t start = 0;
    for (int32_t x = 1; x <= d[0]; ++x) {
      int32_t label = -1;
      if (x < d[0]) {
        if (v[x] != last_value) {
          last_value = v[x];
          label = label_of(v[x]);
        } else {
          label = last_label;
        }
        if (label == last_label) continue;
      }
      if (last_label != 0) emit(start, x, last_label);
      start = x;
      last_label = label;
    }
  };
  std::vector<size_t> count(rows + 1, 0);
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows, 256), [&](const auto& r) {
    throw_if_cancelled(progress);
    for (int64_t row = r.begin(); row < r.end(); ++row) {
      size_t n = 0;
      scan_row(row, [&](int32_t, int32_t, int32_t) { ++n; });
      count[row + 1] = n;
    }
  });
  std::partial_sum(count.begin(), count.end(), count.begin());
  std::vector<RunLabel> runs(count.back());
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows, 256), [&](const auto& r) {
    for (int64_t row = r.begin(); row < r.end(); ++row) {
      size_t at = count[row];
      const int32_t y = static_cast<int32_t>(row % d[1]), z = static_cast<int32_t>(row / d[1]);
      scan_row(row, [&](int32_t x0, int32_t x1, int32_t label) {
        runs[at++] = {{x0, x1, y, z}, label};
      });
    }
  });
  row_first = std::move(count);
  return runs;
}

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

Components join_runs(const std::vector<RunLabel>& runs, const std::vector<size_t>& row_first,
                     const std::array<int64_t, 3>& dims, int connectivity) {
  if (connectivity != 6 && connectivity != 18 && connectivity != 26) {
    throw std::invalid_argument("connected components: connectivity must be 6, 18 or 26");
  }
  const int64_t ny = dims[1], nz = dims[2];
  std::vector<uint32_t> parent(runs.size());
  std::iota(parent.begin(), parent.end(), 0u);

  // Neighbouring rows already visited (dy, dz) and how far runs may be apart in x and still
  // touch (0: they must overlap; 1: they may meet at an edge or corner).
  struct Neighbour {
    int dy, dz, reach;
  };
  std::vector<Neighbour> neighbours;
  if (connectivity == 6) neighbours = {{-1, 0, 0}, {0, -1, 0}};
  if (connectivity == 18) neighbours = {{-1, 0, 1}, {0, -1, 1}, {-1, -1, 0}, {1, -1, 0}};
  if (connectivity == 26) neighbours = {{-1, 0, 1}, {0, -1, 1}, {-1, -1, 1}, {1, -1, 1}};

  for (int64_t z = 0; z < nz; ++z) {
    for (int64_t y = 0; y < ny; ++y) {
      const int64_t row = z * ny + y;
      for (const Neighbour& nb : neighbours) {
        const int64_t y2 = y + nb.dy, z2 = z + nb.dz;
        if (y2 < 0 || y2 >= ny || z2 < 0) continue;
        const int64_t row2 = z2 * ny + y2;
        size_t b = row_first[row2];
        const size_t b_end = row_first[row2 + 1];
        for (size_t a = row_first[row]; a < row_first[row + 1]; ++a) {
          const VoxelRun& ra = runs[a].run;
          while (b < b_end && runs[b].run.x_end + nb.reach <= ra.x_begin) ++b;
          for (size_t m = b; m < b_end && runs[m].run.x_begin < ra.x_end + nb.reach; ++m) {
            if (runs[m].label != runs[a].label) continue;
            const uint32_t ra_root = find_root(parent, uint32_t(a));
            const uint32_t rb_root = find_root(parent, uint32_t(m));
            if (ra_root != rb_root) parent[std::max(ra_root, rb_root)] = std::min(ra_root, rb_root);
          }
        }
      }
    }
  }

  // Gather components in order of their first run, then sort by label and size.
  Components out;
  std::vector<uint32_t> component_of(runs.size());
  std::vector<int64_t> root_to_component(runs.size(), -1);
  for (size_t r = 0; r < runs.size(); ++r) {
    const uint32_t root = find_root(parent, uint32_t(r));
    if (root_to_component[root] < 0) {
      root_to_component[root] = static_cast<int64_t>(out.components.size());
      Component c;
      c.label = runs[r].label;
      c.first = {INT64_MAX, INT64_MAX, INT64_MAX};
      c.last = {INT64_MIN, INT64_MIN, INT64_MIN};
      out.components.push_back(c);
    }
    const auto ci = static_cast<uint32_t>(root_to_component[root]);
    component_of[r] = ci;
    Component& c = out.components[ci];
    const VoxelRun& run = runs[r].run;
    c.voxels += run.x_end - run.x_begin;
    c.run_count += 1;
    c.first = {std::min<int64_t>(c.first[0], run.x_begin), std::min<int64_t>(c.first[1], run.y),
               std::min<int64_t>(c.first[2], run.z)};
    c.last = {std::max<int64_t>(c.last[0], run.x_end - 1), std::max<int64_t>(c.last[1], run.y),
              std::max<int64_t>(c.last[2], run.z)};
  }
  std::vector<uint32_t> order(out.components.size());
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const Component& ca = out.components[a];
    const Component& cb = out.components[b];
    if (ca.label != cb.label) return ca.label < cb.label;
    return ca.voxels > cb.voxels;
  });
  std::vector<uint32_t> rank(order.size());
  std::vector<Component> sorted(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    rank[order[i]] = static_cast<uint32_t>(i);
    sorted[i] = out.components[order[i]];
  }
  size_t next_run = 0;
  for (size_t i = 0; i < sorted.size(); ++i) {
    sorted[i].first_run = next_run;
    next_run += sorted[i].run_count;
    sorted[i].index = (i > 0 && sorted[i - 1].label == sorted[i].label) ? sorted[i - 1].index + 1 : 1;
  }
  out.runs.resize(runs.size());
  std::vector<size_t> fill(sorted.size());
  for (size_t i = 0; i < sorted.size(); ++i) fill[i] = sorted[i].first_run;
  for (size_t r = 0; r < runs.size(); ++r) out.runs[fill[rank[component_of[r]]]++] = runs[r].run;
  out.components = std::move(sorted);
  return out;
}

}  // namespace

Components find_components(const LabelVolume& volume, const ComponentOptions& options,
                           Progress& progress) {
  std::vector<int32_t> wanted = options.labels;
  std::sort(wanted.begin(), wanted.end());
  auto label_of = [&](int32_t v) -> int32_t {
    if (v == 0) return 0;
    if (wanted.empty()) return v;
    return std::binary_search(wanted.begin(), wanted.end(), v) ? v : 0;
  };
  std::vector<size_t> row_first;
  const auto runs = find_runs(volume, label_of, progress, row_first);
  return join_runs(runs, row_first, volume.grid.dims, options.connectivity);
}

template <class T>
Components find_components_above(const Volume<T>& volume, double iso, int connectivity,
                                 Progress& progress) {
  auto label_of = [iso](T v) -> int32_t { return static_cast<double>(v) >= iso ? 1 : 0; };
  std::vector<size_t> row_first;
  const auto runs = find_runs(volume, label_of, progress, row_first);
  return join_runs(runs, row_first, volume.grid.dims, connectivity);
}

template Components find_components_above(const Volume<int32_t>&, double, int, Progress&);
template Components find_components_above(const Volume<float>&, double, int, Progress&);

}  // namespace segmesh
