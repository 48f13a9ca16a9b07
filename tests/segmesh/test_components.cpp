// Connected components: counts, sizes and order against an independent breadth-first search, the
// meaning of 6/18/26-connectivity at edge and corner contacts, label selection, determinism.
#include "segmesh/components.hpp"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <map>

#include "segmesh/component_field.hpp"
#include "support/reference_components.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

using test::random_labels;

// (label, voxels) of every component, sorted as the library sorts them.
std::vector<std::pair<int32_t, int64_t>> reference_sizes(const LabelVolume& v, int connectivity) {
  int count = 0;
  const auto comp = test::reference_label_components(v, connectivity, count);
  std::vector<std::pair<int32_t, int64_t>> sizes(count, {0, 0});
  for (size_t i = 0; i < comp.size(); ++i) {
    if (comp[i] < 0) continue;
    sizes[comp[i]].first = v.voxels[i];
    ++sizes[comp[i]].second;
  }
  std::sort(sizes.begin(), sizes.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first < b.first : a.second > b.second;
  });
  return sizes;
}

TEST(Components, MatchBreadthFirstSearchOnRandomLabelMaps) {
  for (int connectivity : {6, 18, 26}) {
    for (double density : {0.15, 0.4, 0.7}) {
      const auto v = random_labels({23, 17, 19}, 3, density, 11u + unsigned(connectivity));
      const Components c = find_components(v, {.connectivity = connectivity});
      const auto expected = reference_sizes(v, connectivity);
      ASSERT_EQ(c.components.size(), expected.size()) << connectivity << " " << density;
      int64_t runs_voxels = 0;
      for (size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(c.components[i].label, expected[i].first);
        EXPECT_EQ(c.components[i].voxels, expected[i].second);
        int64_t n = 0;
        for (const VoxelRun& r : c.runs_of(c.components[i])) {
          n += r.x_end - r.x_begin;
          for (int32_t x = r.x_begin; x < r.x_end; ++x)
            ASSERT_EQ(v.at(x, r.y, r.z), c.components[i].label);
        }
        EXPECT_EQ(n, c.components[i].voxels);
        runs_voxels += n;
      }
      EXPECT_EQ(runs_voxels, std::count_if(v.voxels.begin(), v.voxels.end(),
                                           [](int32_t x) { return x != 0; }));
    }
  }
}

// components_touch against the definition: some voxel of one chosen component has a voxel of
// another chosen component among its 26 neighbours.
TEST(Components, TouchingMatchesTheVoxelDefinitionOnRandomMaps) {
  int touching = 0, apart = 0;
  for (int connectivity : {6, 26}) {
    for (unsigned seed = 1; seed <= 12; ++seed) {
      const auto v = random_labels({13, 11, 9}, 3, 0.08 + 0.02 * seed, seed);
      const Components c = find_components(v, {.connectivity = connectivity});
      std::vector<int> owner(v.voxels.size(), -1);
      for (size_t k = 0; k < c.components.size(); ++k)
        for (const VoxelRun& r : c.runs_of(c.components[k]))
          for (int32_t x = r.x_begin; x < r.x_end; ++x) owner[size_t(v.grid.index(x, r.y, r.z))] = int(k);
      // Every pair of components, and all of them.
      std::vector<std::vector<size_t>> sets;
      for (size_t a = 0; a < c.components.size() && a < 6; ++a)
        for (size_t b = a + 1; b < c.components.size() && b < 6; ++b) sets.push_back({a, b});
      std::vector<size_t> all(c.components.size());
      for (size_t k = 0; k < all.size(); ++k) all[k] = k;
      sets.push_back(all);
      for (const auto& which : sets) {
        std::vector<char> chosen(c.components.size(), 0);
        for (size_t k : which) chosen[k] = 1;
        bool expected = false;
        const auto d = v.grid.dims;
        for (int64_t z = 0; z < d[2] && !expected; ++z)
          for (int64_t y = 0; y < d[1] && !expected; ++y)
            for (int64_t x = 0; x < d[0] && !expected; ++x) {
              const int a = owner[size_t(v.grid.index(x, y, z))];
              if (a < 0 || !chosen[size_t(a)]) continue;
              for (int64_t dz = -1; dz <= 1; ++dz)
                for (int64_t dy = -1; dy <= 1; ++dy)
                  for (int64_t dx = -1; dx <= 1; ++dx) {
                    const int64_t i = x + dx, j = y + dy, k = z + dz;
                    if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2]) continue;
                    const int b = owner[size_t(v.grid.index(i, j, k))];
                    if (b >= 0 && b != a && chosen[size_t(b)]) expected = true;
                  }
            }
        EXPECT_EQ(components_touch(c, which), expected) << connectivity << " " << seed;
        (expected ? touching : apart) += 1;
      }
    }
  }
  EXPECT_GT(touching, 10);  // both answers occur
  EXPECT_GT(apart, 10);
}

TEST(Components, NumberedWithinLabelLargestFirstWithBoundingBoxes) {
  LabelVolume v;
  v.grid.dims = {10, 6, 5};
  v.voxels.assign(v.grid.voxel_count(), 0);
  v.at(1, 1, 1) = 4;                                   // label 4, 1 voxel
  for (int i = 3; i < 8; ++i) v.at(i, 2, 3) = 4;       // label 4, 5 voxels
  v.at(9, 5, 4) = 2;                                   // label 2, 1 voxel at the far corner
  const Components c = find_components(v, {});
  ASSERT_EQ(c.components.size(), 3u);
  EXPECT_EQ(c.components[0].label, 2);
  EXPECT_EQ(c.components[0].index, 1);
  EXPECT_EQ(c.components[1].label, 4);
  EXPECT_EQ(c.components[1].index, 1);
  EXPECT_EQ(c.components[1].voxels, 5);
  EXPECT_EQ(c.components[1].first, (std::array<int64_t, 3>{3, 2, 3}));
  EXPECT_EQ(c.components[1].last, (std::array<int64_t, 3>{7, 2, 3}));
  EXPECT_EQ(c.components[2].index, 2);
  EXPECT_EQ(c.components[0].first, (std::array<int64_t, 3>{9, 5, 4}));
}

TEST(Components, EdgeAndCornerContactsFollowTheConnectivity) {
  auto two_voxels = [](std::array<int64_t, 3> offset) {
    LabelVolume v;
    v.grid.dims = {4, 4, 4};
    v.voxels.assign(64, 0);
    v.at(1, 1, 1) = 1;
    v.at(1 + offset[0], 1 + offset[1], 1 + offset[2]) = 1;
    return v;
  };
  const auto face = two_voxels({1, 0, 0}), edge = two_voxels({1, 1, 0}),
             edge_yz = two_voxels({0, 1, 1}), corner = two_voxels({1, 1, 1}),
             corner_back = two_voxels({-1, 1, 1});
  auto count = [](const LabelVolume& v, int c) {
    return find_components(v, {.connectivity = c}).components.size();
  };
  EXPECT_EQ(count(face, 6), 1u);
  EXPECT_EQ(count(edge, 6), 2u);
  EXPECT_EQ(count(edge, 18), 1u);
  EXPECT_EQ(count(edge_yz, 18), 1u);
  EXPECT_EQ(count(corner, 18), 2u);
  EXPECT_EQ(count(corner, 26), 1u);
  EXPECT_EQ(count(corner_back, 26), 1u);
  EXPECT_EQ(count(corner_back, 18), 2u);
}

TEST(Components, SelectedLabelsOnlyAndGreyValueThreshold) {
  const auto v = random_labels({12, 11, 10}, 4, 0.5, 5);
  const Components c = find_components(v, {.labels = {3, 1}});
  ASSERT_FALSE(c.components.empty());
  for (const Component& comp : c.components) EXPECT_TRUE(comp.label == 1 || comp.label == 3);

  // Threshold at 2.5 selects labels 3 and 4 as one class.
  const Components above = find_components_above(v, 2.5, 26);
  int count = 0;
  test::reference_components(
      v, 26, [](int32_t x) { return x >= 3; }, [](int32_t, int32_t) { return true; }, count);
  EXPECT_EQ(above.components.size(), size_t(count));
  for (const Component& comp : above.components) EXPECT_EQ(comp.label, 1);
}

TEST(Components, IdenticalForAnyThreadCount) {
  const auto v = random_labels({64, 48, 40}, 3, 0.45, 9);
  Components one, many;
  tbb::task_arena(1).execute([&] { one = find_components(v, {}); });
  tbb::task_arena(4).execute([&] { many = find_components(v, {}); });
  ASSERT_EQ(one.components.size(), many.components.size());
  for (size_t i = 0; i < one.components.size(); ++i) {
    EXPECT_EQ(one.components[i].voxels, many.components[i].voxels);
    EXPECT_EQ(one.components[i].first_run, many.components[i].first_run);
  }
  ASSERT_EQ(one.runs.size(), many.runs.size());
  for (size_t i = 0; i < one.runs.size(); ++i) {
    EXPECT_EQ(one.runs[i].x_begin, many.runs[i].x_begin);
    EXPECT_EQ(one.runs[i].y, many.runs[i].y);
  }
}

TEST(ComponentField, MaskHoldsExactlyTheComponentWithAMarginInWorldPlace) {
  LabelVolume v = random_labels({20, 15, 12}, 2, 0.3, 21);
  v.grid.spacing = {0.5, 0.7, 2.0};
  v.grid.origin = {10, -20, 30};
  const Components c = find_components(v, {});
  const Component& big = c.components.front();
  const auto mask = component_mask(v.grid, c, big);
  EXPECT_EQ(mask.grid.dims[0], big.last[0] - big.first[0] + 1 + 2 * kFieldMargin);
  int64_t ones = 0;
  for (uint8_t x : mask.voxels) ones += x;
  EXPECT_EQ(ones, big.voxels);
  // Mask voxel (m, n, p) is volume voxel (first - margin + (m, n, p)), at the same world point.
  const VoxelRun& r = c.runs_of(big).front();
  const int64_t mi = r.x_begin - big.first[0] + kFieldMargin, mj = r.y - big.first[1] + kFieldMargin,
                mk = r.z - big.first[2] + kFieldMargin;
  EXPECT_EQ(mask.at(mi, mj, mk), 1);
  const Vec3d a = mask.grid.to_world({double(mi), double(mj), double(mk)});
  const Vec3d b = v.grid.to_world({double(r.x_begin), double(r.y), double(r.z)});
  EXPECT_NEAR(norm(a - b), 0.0, 1e-9);
  // The margin is empty.
  for (int64_t j = 0; j < mask.grid.dims[1]; ++j)
    for (int64_t i = 0; i < mask.grid.dims[0]; ++i) EXPECT_EQ(mask.at(i, j, 0), 0);
}

}  // namespace
}  // namespace segmesh
