// Marching Cubes straight from a component's runs (run_scan.hpp) against Marching Cubes of the
// component's mask: the same triangles on the same vertices, for every connectivity, on random
// label maps with parts that touch the volume border, on mirrored and rotated grids, and for any
// thread count; and the scan's interval arithmetic against a voxel-by-voxel count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstring>
#include <random>

#include "segmesh/component_field.hpp"
#include "segmesh/components.hpp"
#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/detail/run_scan.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

// Label maps of random voxels with labels 1 .. 3, filling the volume to its border.
LabelVolume random_labels(std::array<int64_t, 3> dims, double density, unsigned seed) {
  return test::random_labels(dims, 3, density, seed);
}

void expect_same_mesh(const TriMesh& runs, const TriMesh& mask, double tolerance_mm,
                      const std::string& what) {
  ASSERT_EQ(runs.indices, mask.indices) << what;
  ASSERT_EQ(runs.positions.size(), mask.positions.size()) << what;
  EXPECT_TRUE(runs.normals.empty()) << what;
  double worst = 0;
  for (size_t v = 0; v < runs.positions.size(); ++v) {
    const Vec3f a = runs.positions[v], b = mask.positions[v];
    worst = std::max({worst, double(std::abs(a.x - b.x)), double(std::abs(a.y - b.y)),
                      double(std::abs(a.z - b.z))});
  }
  EXPECT_LE(worst, tolerance_mm) << what;
}

TEST(MarchingCubesRuns, SameMeshAsTheMaskForEveryComponentAndConnectivity) {
  LabelVolume labels = random_labels({23, 17, 19}, 0.45, 3);
  labels.grid.spacing = {0.7, 0.45, 1.9};
  labels.grid.origin = {-12, 30, 5};
  int compared = 0;
  for (int connectivity : {6, 18, 26}) {
    const Components c = find_components(labels, {.connectivity = connectivity});
    ASSERT_GT(c.components.size(), 3u);
    for (const Component& part : c.components) {
      const McOptions o{.connectivity = connectivity, .vertex_normals = false};
      const TriMesh runs = marching_cubes(labels.grid, c, part, o);
      const TriMesh mask = marching_cubes(component_mask(labels.grid, c, part), o);
      ASSERT_FALSE(runs.empty());
      const std::string what = "label " + std::to_string(part.label) + " component " +
                               std::to_string(part.index) + " connectivity " +
                               std::to_string(connectivity);
      expect_same_mesh(runs, mask, 1e-4, what);
      const MeshMeasures m = measure_mesh(runs);
      EXPECT_TRUE(m.closed()) << what;
      EXPECT_EQ(m.nonmanifold_vertices, 0) << what;
      EXPECT_GT(m.volume_mm3, 0) << what;
      ++compared;
    }
  }
  EXPECT_GT(compared, 30);
}

TEST(MarchingCubesRuns, MirroredRotatedGridsAndFullRows) {
  // A solid box filling whole rows (runs from x = 0 to the last voxel), with a tunnel, on a
  // rotated and mirrored grid.
  LabelVolume labels;
  labels.grid.dims = {12, 9, 7};
  labels.grid.spacing = {0.3, 0.6, 1.5};
  const double a = 0.4, c = std::cos(a), s = std::sin(a);
  labels.grid.direction = Mat3d{-c, -s, 0, -s, c, 0, 0, 0, 1};  // determinant -1
  labels.voxels.assign(labels.grid.voxel_count(), 1);
  for (int64_t i = 0; i < 12; ++i) labels.at(i, 4, 3) = 0;
  const Components comps = find_components(labels, {});
  ASSERT_EQ(comps.components.size(), 1u);
  const McOptions o{.vertex_normals = false};
  const TriMesh runs = marching_cubes(labels.grid, comps, comps.components[0], o);
  const TriMesh mask = marching_cubes(component_mask(labels.grid, comps, comps.components[0]), o);
  expect_same_mesh(runs, mask, 1e-4, "box with tunnel");
  const MeshMeasures m = measure_mesh(runs);
  EXPECT_TRUE(m.closed()) << "box with tunnel";
  EXPECT_EQ(m.nonmanifold_vertices, 0) << "box with tunnel";
  EXPECT_GT(m.volume_mm3, 0);  // outward winding on the mirrored grid
  EXPECT_EQ(m.euler, 0);  // a tunnel through: genus 1
}

TEST(MarchingCubesRuns, NormalsRequestedComeFromTheMaskField) {
  LabelVolume labels = random_labels({10, 11, 9}, 0.6, 8);
  const Components comps = find_components(labels, {});
  const Component& part = comps.components[0];
  const TriMesh runs = marching_cubes(labels.grid, comps, part, {});
  const TriMesh mask = marching_cubes(component_mask(labels.grid, comps, part), {});
  EXPECT_EQ(runs.indices, mask.indices);
  ASSERT_EQ(runs.normals.size(), runs.positions.size());
  EXPECT_EQ(0, std::memcmp(runs.normals.data(), mask.normals.data(), runs.normals.size() * sizeof(Vec3f)));
}

TEST(MarchingCubesRuns, IdenticalForAnyThreadCount) {
  const LabelVolume labels = random_labels({60, 50, 40}, 0.55, 21);
  const Components comps = find_components(labels, {});
  const Component& part = comps.components[0];
  TriMesh one, many;
  tbb::task_arena(1).execute([&] { one = marching_cubes(labels.grid, comps, part, {.vertex_normals = false}); });
  tbb::task_arena(4).execute([&] { many = marching_cubes(labels.grid, comps, part, {.vertex_normals = false}); });
  ASSERT_GT(one.triangle_count(), 10000u);
  EXPECT_TRUE(test::identical(one, many));
}

TEST(RunScan, EdgeCountsAndCellsAgreeWithTheMask) {
  const LabelVolume labels = random_labels({15, 13, 11}, 0.5, 5);
  const Components comps = find_components(labels, {.connectivity = 6});
  for (const Component& part : comps.components) {
    const RunScan scan(labels.grid, comps, part);
    const Volume<uint8_t> mask = component_mask(labels.grid, comps, part, {1, 1, 1});
    ASSERT_EQ(scan.dims(), mask.grid.dims);
    const auto& d = mask.grid.dims;
    for (int64_t k = 0; k < d[2]; ++k) {
      for (int64_t j = 0; j < d[1]; ++j) {
        for (int axis = 0; axis < 3; ++axis) {
          std::vector<int64_t> expected, seen;
          for (int64_t i = 0; i < d[0]; ++i) {
            const int64_t i1 = i + (axis == 0), j1 = j + (axis == 1), k1 = k + (axis == 2);
            if (i1 >= d[0] || j1 >= d[1] || k1 >= d[2]) continue;
            if (mask.at(i, j, k) != mask.at(i1, j1, k1)) expected.push_back(i);
          }
          scan.row_edges(axis, j, k, [&](int64_t i) { seen.push_back(i); });
          ASSERT_EQ(seen, expected) << "axis " << axis << " row " << j << ", " << k;
          ASSERT_EQ(scan.row_edge_count(axis, j, k), int64_t(expected.size()));
        }
        if (j + 1 >= d[1] || k + 1 >= d[2]) continue;
        std::vector<std::pair<int64_t, int>> expected, seen;
        for (int64_t i = 0; i + 1 < d[0]; ++i) {
          int cs = 0;
          for (int corner = 0; corner < 8; ++corner) {
            cs |= mask.at(i + (corner & 1), j + (corner >> 1 & 1), k + (corner >> 2)) << corner;
          }
          if (cs != 0 && cs != 255) expected.push_back({i, cs});
        }
        scan.cells(j, k, [&](int64_t i, int cs) { seen.push_back({i, cs}); });
        ASSERT_EQ(seen, expected) << "cells of row " << j << ", " << k;
        ASSERT_EQ(scan.cell_sum(j, k, [](int cs) { return int64_t{cs != 0 && cs != 255}; }),
                  int64_t(expected.size()));
      }
    }
  }
}

}  // namespace
}  // namespace segmesh
