#include "segmesh/components.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cstring>
#include <numeric>
#include <stdexcept>

namespace segmesh {

namespace {

// The first x >= from with v[x] != value, or n. Label maps hold long stretches of one value:
// 64 bytes at a time are compared as eight words against the value repeated (a voxel loop is
// not vectorised by the compiler because of its early exit).
template <class T>
int64_t skip_equal(const T* v, int64_t from, int64_t n, T value) {
  constexpr int64_t kBlock = 64 / sizeof(T);
  uint64_t pattern = 0;
  for (size_t b = 0; b < sizeof(pattern) / sizeof(T); ++b) {
    std::memcpy(reinterpret_cast<unsigned char*>(&pattern) + b * sizeof(T), &value, sizeof(T));
  }
  int64_t x = from;
  while (x + kBlock <= n) {
    uint64_t words[8];
    std::memcpy(words, v + x, sizeof(words));
    uint64_t diff = 0;
    for (uint64_t w : words) diff |= w ^ pattern;
    if (diff != 0) break;
    x += kBlock;
  }
  while (x < n && v[x] == value) ++x;
  return x;
}

// Finds the runs of every row in one pass: rows are split into fixed chunks, each chunk collects
// its runs on its own, and the chunks are joined in row order (so the result does not depend on the
// thread count). `label_of(value)` gives a voxel's label (0 = not wanted).
template <class T, class LabelOf>
LabelRuns scan_runs(const Volume<T>& volume, LabelOf label_of, Progress& progress) {
  const auto& d = volume.grid.dims;
  const int64_t rows = d[1] * d[2];
  LabelRuns out;
  out.dims = d;
  out.row_first.assign(static_cast<size_t>(rows) + 1, 0);
  if (rows == 0 || d[0] == 0) return out;
  constexpr int64_t kChunk = 1024;
  const int64_t chunks = (rows + kChunk - 1) / kChunk;
  std::vector<std::vector<LabelRun>> found(static_cast<size_t>(chunks));
  std::atomic<int64_t> chunks_done{0};
  tbb::parallel_for(int64_t{0}, chunks, [&](int64_t c) {
    throw_if_cancelled(progress);
    std::vector<LabelRun>& local = found[static_cast<size_t>(c)];
    for (int64_t row = c * kChunk; row < std::min(rows, (c + 1) * kChunk); ++row) {
      const T* v = volume.voxels.data() + static_cast<size_t>(row) * d[0];
      const int32_t y = static_cast<int32_t>(row % d[1]), z = static_cast<int32_t>(row / d[1]);
      const int64_t nx = d[0];
      T last_value = v[0];
      int32_t last_label = label_of(v[0]);
      int32_t start = 0;
      for (int64_t x = skip_equal(v, 1, nx, last_value); x < nx; x = skip_equal(v, x + 1, nx, last_value)) {
        last_value = v[x];
        const int32_t label = label_of(last_value);
        if (label == last_label) continue;
        if (last_label != 0) local.push_back({{start, static_cast<int32_t>(x), y, z}, last_label});
        start = static_cast<int32_t>(x);
        last_label = label;
      }
      if (last_label != 0) local.push_back({{start, static_cast<int32_t>(nx), y, z}, last_label});
      out.row_first[static_cast<size_t>(row) + 1] = local.size();  // within the chunk for now
    }
    progress.update(double(++chunks_done) / double(chunks));
  });
  // Chunk-local row ends to global row starts.
  size_t total = 0;
  for (int64_t c = 0; c < chunks; ++c) {
    for (int64_t row = c * kChunk; row < std::min(rows, (c + 1) * kChunk); ++row) {
      out.row_first[static_cast<size_t>(row) + 1] += total;
    }
    total += found[static_cast<size_t>(c)].size();
  }
  out.runs.reserve(total);
  for (auto& local : found) out.runs.insert(out.runs.end(), local.begin(), local.end());
  return out;
}

uint32_t find_root(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

Components join(const std::vector<LabelRun>& runs, const std::vector<size_t>& row_first,
                const std::array<int64_t, 3>& dims, int connectivity) {
  require_connectivity(connectivity, "connected components");
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

template <class T>
LabelRuns find_label_runs(const Volume<T>& volume, Progress& progress) {
  return scan_runs(volume, [](T v) { return static_cast<int32_t>(v); }, progress);
}

template <class T>
LabelRuns find_runs_above(const Volume<T>& volume, double iso, Progress& progress) {
  return scan_runs(volume, [iso](T v) -> int32_t { return static_cast<double>(v) >= iso ? 1 : 0; },
                   progress);
}

template LabelRuns find_label_runs(const Volume<uint8_t>&, Progress&);
template LabelRuns find_label_runs(const Volume<int16_t>&, Progress&);
template LabelRuns find_label_runs(const Volume<uint16_t>&, Progress&);
template LabelRuns find_label_runs(const Volume<int32_t>&, Progress&);
template LabelRuns find_runs_above(const Volume<uint8_t>&, double, Progress&);
template LabelRuns find_runs_above(const Volume<int16_t>&, double, Progress&);
template LabelRuns find_runs_above(const Volume<uint16_t>&, double, Progress&);
template LabelRuns find_runs_above(const Volume<int32_t>&, double, Progress&);
template LabelRuns find_runs_above(const Volume<float>&, double, Progress&);

std::vector<LabelCount> count_run_labels(const LabelRuns& runs) {
  std::vector<std::pair<int32_t, int64_t>> lengths;
  lengths.reserve(runs.runs.size());
  for (const LabelRun& r : runs.runs) lengths.push_back({r.label, r.run.x_end - r.run.x_begin});
  std::sort(lengths.begin(), lengths.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<LabelCount> out;
  int64_t foreground = 0;
  for (const auto& [label, n] : lengths) {
    if (out.empty() || out.back().label != label) out.push_back({label, 0});
    out.back().voxels += n;
    foreground += n;
  }
  const int64_t all = runs.dims[0] * runs.dims[1] * runs.dims[2];
  if (all > foreground) {
    out.insert(std::lower_bound(out.begin(), out.end(), 0,
                                [](const LabelCount& c, int32_t l) { return c.label < l; }),
               LabelCount{0, all - foreground});
  }
  return out;
}

Components join_runs(const LabelRuns& runs, const ComponentOptions& options) {
  if (options.labels.empty()) return join(runs.runs, runs.row_first, runs.dims, options.connectivity);
  std::vector<int32_t> wanted = options.labels;
  std::sort(wanted.begin(), wanted.end());
  std::vector<LabelRun> kept;
  std::vector<size_t> row_first(runs.row_first.size(), 0);
  for (size_t row = 0; row + 1 < runs.row_first.size(); ++row) {
    for (size_t r = runs.row_first[row]; r < runs.row_first[row + 1]; ++r) {
      if (std::binary_search(wanted.begin(), wanted.end(), runs.runs[r].label)) {
        kept.push_back(runs.runs[r]);
      }
    }
    row_first[row + 1] = kept.size();
  }
  return join(kept, row_first, runs.dims, options.connectivity);
}

template <class T>
Components find_components(const Volume<T>& volume, const ComponentOptions& options,
                           Progress& progress) {
  return join_runs(find_label_runs(volume, progress), options);
}

template <class T>
Components find_components_above(const Volume<T>& volume, double iso, int connectivity,
                                 Progress& progress) {
  return join_runs(find_runs_above(volume, iso, progress), {.connectivity = connectivity});
}

template Components find_components(const Volume<uint8_t>&, const ComponentOptions&, Progress&);
template Components find_components(const Volume<int16_t>&, const ComponentOptions&, Progress&);
template Components find_components(const Volume<uint16_t>&, const ComponentOptions&, Progress&);
template Components find_components(const Volume<int32_t>&, const ComponentOptions&, Progress&);
template Components find_components_above(const Volume<uint8_t>&, double, int, Progress&);
template Components find_components_above(const Volume<int16_t>&, double, int, Progress&);
template Components find_components_above(const Volume<uint16_t>&, double, int, Progress&);
template Components find_components_above(const Volume<int32_t>&, double, int, Progress&);
template Components find_components_above(const Volume<float>&, double, int, Progress&);

bool components_touch(const Components& c, const std::vector<size_t>& which) {
  if (which.size() < 2) return false;
  // The runs bucketed by row (z, y) over the parts' bounding box, with an empty row before and
  // after every slice's rows and an empty slice at the end, so the neighbour rows of every run
  // exist and never wrap into another slice. A counting sort: no comparison sort of the runs.
  std::array<int64_t, 3> lo = c.components[which[0]].first, hi = c.components[which[0]].last;
  for (size_t k : which)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], c.components[k].first[a]);
      hi[a] = std::max(hi[a], c.components[k].last[a]);
    }
  const int64_t rows_per_slice = hi[1] - lo[1] + 3;
  const size_t rows = size_t((hi[2] - lo[2] + 2) * rows_per_slice);
  auto row_of = [&](const VoxelRun& r) {
    return size_t((r.z - lo[2]) * rows_per_slice + (r.y - lo[1] + 1));
  };
  struct Run {
    int32_t x_begin, x_end;
    uint32_t part;
  };
  std::vector<uint32_t> first(rows + 1, 0);
  for (size_t k : which)
    for (const VoxelRun& r : c.runs_of(c.components[k])) ++first[row_of(r) + 1];
  for (size_t r = 0; r < rows; ++r) first[r + 1] += first[r];
  std::vector<Run> runs(first[rows]);
  std::vector<uint32_t> fill(first.begin(), first.end() - 1);
  for (size_t p = 0; p < which.size(); ++p)
    for (const VoxelRun& r : c.runs_of(c.components[which[p]]))
      runs[fill[row_of(r)]++] = {r.x_begin, r.x_end, uint32_t(p)};
  // Each run against the other runs of its own row and of the four rows after its own that hold
  // 26-neighbours ((y + 1, z), and (y - 1 .. y + 1, z + 1)); the other four are covered from the
  // other side. Rows hold a few runs each, so they are scanned whole. Runs of one row are
  // disjoint: two of them touch when one ends where the other begins.
  const size_t offsets[] = {0, 1, size_t(rows_per_slice) - 1, size_t(rows_per_slice),
                            size_t(rows_per_slice) + 1};
  for (size_t row = 0; row + size_t(rows_per_slice) + 1 < rows; ++row)
    for (uint32_t i = first[row]; i < first[row + 1]; ++i) {
      const Run& a = runs[i];
      for (size_t d : offsets)
        for (uint32_t k = first[row + d]; k < first[row + d + 1]; ++k) {
          const Run& b = runs[k];
          if (b.part != a.part && b.x_begin <= a.x_end && b.x_end >= a.x_begin) return true;
        }
    }
  return false;
}

}  // namespace segmesh
