// Connected components of the labels of a volume, in linear time: union-find over runs.
//
// Each row of voxels (fixed y, z) is cut into runs of one label; a run is joined with the runs of
// the same label in the neighbouring rows that touch it under the chosen connectivity (6: faces,
// 18: faces and edges, 26: faces, edges and corners — the default, as in the reference method's
// region growing). Runs are a compact description of a component (a few per row instead of a
// label per voxel), so no volume-sized component map is ever allocated; the runs are found in
// parallel over z-slices and joined in one pass, and the result is the same for any thread count.
//
// Components are ordered by label, then by size (largest first; ties by position), and numbered
// 1, 2, ... within their label. Nothing is dropped here.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "segmesh/connectivity.hpp"
#include "segmesh/label_stats.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

struct VoxelRun {
  int32_t x_begin = 0, x_end = 0;  // voxels [x_begin, x_end) of row (y, z)
  int32_t y = 0, z = 0;
};

struct Component {
  int32_t label = 0;
  int index = 1;  // 1 = the largest component of its label
  int64_t voxels = 0;
  std::array<int64_t, 3> first{};  // bounding box in index space, inclusive
  std::array<int64_t, 3> last{};
  size_t first_run = 0, run_count = 0;  // its runs in Components::runs
};

struct Components {
  std::vector<VoxelRun> runs;              // grouped by component, each group in (z, y, x) order
  std::vector<Component> components;  // by label, then largest first

  std::span<const VoxelRun> runs_of(const Component& c) const {
    return {runs.data() + c.first_run, c.run_count};
  }
};

// The runs of every row (label > 0 only), in row order: rows [row_first[r], row_first[r + 1]).
struct LabelRun {
  VoxelRun run;
  int32_t label = 0;
};
struct LabelRuns {
  std::array<int64_t, 3> dims{};
  std::vector<LabelRun> runs;
  std::vector<size_t> row_first;  // rows + 1 entries
};

struct ComponentOptions {
  int connectivity = kDefaultConnectivity;  // 6, 18 or 26
  std::vector<int32_t> labels;   // labels to split; empty: every non-zero label
};

// The runs of every non-zero label: one parallel pass over the voxels (T: an integer voxel type of
// AnyVolume).
template <class T>
LabelRuns find_label_runs(const Volume<T>& volume, Progress& progress = null_progress());
// The runs of the voxels whose value is >= iso, as label 1.
template <class T>
LabelRuns find_runs_above(const Volume<T>& volume, double iso, Progress& progress = null_progress());
// Voxels per label (0 included, as everything not in a run), ascending, from the runs alone.
std::vector<LabelCount> count_run_labels(const LabelRuns& runs);
// Components of the runs' labels (options.labels selects; empty: all).
Components join_runs(const LabelRuns& runs, const ComponentOptions& options);

// Components of the labels of a label map (find_label_runs, then join_runs).
template <class T>
Components find_components(const Volume<T>& volume, const ComponentOptions& options,
                           Progress& progress = null_progress());

// Components of the voxels whose value is >= iso (a grey-value volume); they get label 1.
// Whether two of the given components (indices into c.components) touch: a voxel of one and a
// voxel of another are 26-neighbours, so some Marching Cubes cell holds both. When none touch,
// every cell holds one component at most and meshing them together is meshing them one by one
// (the pipeline then takes the cheaper path). O(R log R) for R runs of the given components.
bool components_touch(const Components& c, const std::vector<size_t>& which);

template <class T>
Components find_components_above(const Volume<T>& volume, double iso, int connectivity,
                                 Progress& progress = null_progress());

extern template LabelRuns find_label_runs(const Volume<uint8_t>&, Progress&);
extern template LabelRuns find_label_runs(const Volume<int16_t>&, Progress&);
extern template LabelRuns find_label_runs(const Volume<uint16_t>&, Progress&);
extern template LabelRuns find_label_runs(const Volume<int32_t>&, Progress&);
extern template Components find_components(const Volume<uint8_t>&, const ComponentOptions&, Progress&);
extern template Components find_components(const Volume<int16_t>&, const ComponentOptions&, Progress&);
extern template Components find_components(const Volume<uint16_t>&, const ComponentOptions&, Progress&);
extern template Components find_components(const Volume<int32_t>&, const ComponentOptions&, Progress&);
extern template LabelRuns find_runs_above(const Volume<uint8_t>&, double, Progress&);
extern template LabelRuns find_runs_above(const Volume<int16_t>&, double, Progress&);
extern template LabelRuns find_runs_above(const Volume<uint16_t>&, double, Progress&);
extern template LabelRuns find_runs_above(const Volume<int32_t>&, double, Progress&);
extern template LabelRuns find_runs_above(const Volume<float>&, double, Progress&);
extern template Components find_components_above(const Volume<uint8_t>&, double, int, Progress&);
extern template Components find_components_above(const Volume<int16_t>&, double, int, Progress&);
extern template Components find_components_above(const Volume<uint16_t>&, double, int, Progress&);
extern template Components find_components_above(const Volume<int32_t>&, double, int, Progress&);
extern template Components find_components_above(const Volume<float>&, double, int, Progress&);

}  // namespace segmesh
