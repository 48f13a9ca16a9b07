// Dual Contouring of a label part from its runs (inside bits set run by run, inside_bits.hpp)
// against Dual Contouring of the part's mask: the same mesh, for every connectivity and both normal
// operators, on random label maps whose parts touch the volume border, and on rows across word
// boundaries; the same without normals; identical for any thread count.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <stdexcept>
#include <vector>

#include "segmesh/component_field.hpp"
#include "segmesh/components.hpp"
#include "segmesh/dual_contouring.hpp"
#include "segmesh/mesh_measures.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

using test::identical;

// Label maps of random voxels with labels 1 and 2, filling the volume to its border.
LabelVolume random_labels(std::array<int64_t, 3> dims, double density, unsigned seed) {
  return test::random_labels(dims, 2, density, seed);
}

TEST(DualContouringRuns, SameMeshAsTheMaskForEveryComponent) {
  LabelVolume labels = random_labels({19, 15, 13}, 0.5, 7);
  labels.grid.spacing = {0.6, 0.45, 1.7};
  labels.grid.origin = {3, -20, 11};
  int compared = 0;
  for (int connectivity : {6, 18, 26}) {
    for (NormalMethod normals : {NormalMethod::central, NormalMethod::sobel}) {
      const Components c = find_components(labels, {.connectivity = connectivity});
      for (const Component& part : c.components) {
        const DcOptions o{.connectivity = connectivity, .normals = normals};
        const TriMesh runs = dual_contouring(labels.grid, c, part, o);
        const TriMesh mask = dual_contouring(component_mask(labels.grid, c, part), o);
        ASSERT_FALSE(runs.empty());
        EXPECT_TRUE(identical(runs, mask)) << "label " << part.label << " component " << part.index
                                           << " connectivity " << connectivity;
        EXPECT_TRUE(measure_mesh(runs).closed());
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 20);
}

// Rows longer than one word of 64 cells (dual_contouring.cpp numbers cells by popcounts per
// word): edges and quadrant cells on both sides of every word boundary.
TEST(DualContouringRuns, SameMeshAsTheMaskAcrossWordBoundaries) {
  for (int64_t nx : {62, 63, 64, 65, 127, 128, 131}) {
    LabelVolume labels = random_labels({nx, 7, 6}, 0.55, unsigned(nx));
    labels.grid.spacing = {0.4, 0.9, 1.3};
    for (int connectivity : {6, 26}) {
      const Components c = find_components(labels, {.connectivity = connectivity});
      for (const Component& part : c.components) {
        const DcOptions o{.connectivity = connectivity};
        const TriMesh runs = dual_contouring(labels.grid, c, part, o);
        const TriMesh mask = dual_contouring(component_mask(labels.grid, c, part), o);
        EXPECT_TRUE(identical(runs, mask)) << "nx " << nx << " connectivity " << connectivity;
        const MeshMeasures m = measure_mesh(runs);
        EXPECT_TRUE(m.closed()) << "nx " << nx << " connectivity " << connectivity;
        EXPECT_EQ(m.nonmanifold_vertices, 0) << "nx " << nx;
      }
    }
  }
}

// Without vertex normals (what the pipeline asks for when smoothing follows): the same vertices
// and triangles, no normals.
TEST(DualContouringRuns, WithoutNormalsSameVerticesAndTriangles) {
  const LabelVolume labels = random_labels({70, 20, 16}, 0.5, 5);
  const Components c = find_components(labels, {});
  const TriMesh with = dual_contouring(labels.grid, c, c.components[0], {});
  const TriMesh without =
      dual_contouring(labels.grid, c, c.components[0], {.vertex_normals = false});
  ASSERT_EQ(with.normals.size(), with.positions.size());
  EXPECT_TRUE(without.normals.empty());
  EXPECT_EQ(with.indices, without.indices);
  TriMesh stripped = with;
  stripped.normals.clear();
  EXPECT_TRUE(identical(stripped, without));
}

TEST(DualContouringRuns, IdenticalForAnyThreadCount) {
  const LabelVolume labels = random_labels({150, 40, 36}, 0.55, 13);
  const Components c = find_components(labels, {});
  TriMesh one, many;
  tbb::task_arena(1).execute([&] { one = dual_contouring(labels.grid, c, c.components[0], {}); });
  tbb::task_arena(4).execute([&] { many = dual_contouring(labels.grid, c, c.components[0], {}); });
  ASSERT_GT(one.triangle_count(), 10000u);
  EXPECT_TRUE(identical(one, many));
}

// The parts of one label map sharing their solved neighbourhoods (what extract_parts does), in
// parallel at four threads: every part gets the mesh it gets with its own, bit for bit. Tables
// made for another spacing or other options are refused.
TEST(DualContouringRuns, SharedNeighbourhoodsGiveEachPartItsOwnMesh) {
  LabelVolume labels = random_labels({40, 30, 26}, 0.5, 21);
  labels.grid.spacing = {0.8, 0.8, 1.25};
  const Components c = find_components(labels, {});
  ASSERT_GT(c.components.size(), 5u);
  const DcOptions o{.vertex_normals = true};
  DcNeighbourhoods solved(labels.grid, o);
  std::vector<TriMesh> shared(c.components.size());
  tbb::task_arena(4).execute([&] {
    tbb::parallel_for(size_t{0}, c.components.size(), [&](size_t p) {
      shared[p] = dual_contouring(labels.grid, c, c.components[p], o, null_progress(), &solved);
    });
  });
  for (size_t p = 0; p < c.components.size(); ++p) {
    EXPECT_TRUE(identical(shared[p], dual_contouring(labels.grid, c, c.components[p], o)))
        << "component " << p;
  }
  Grid other = labels.grid;
  other.spacing[2] = 1.5;
  DcNeighbourhoods elsewhere(other, o);
  EXPECT_THROW(dual_contouring(labels.grid, c, c.components[0], o, null_progress(), &elsewhere),
               std::logic_error);
  DcNeighbourhoods sobel(labels.grid, {.normals = NormalMethod::sobel, .vertex_normals = true});
  EXPECT_THROW(dual_contouring(labels.grid, c, c.components[0], o, null_progress(), &sobel),
               std::logic_error);
  DcNeighbourhoods no_normals(labels.grid, {.vertex_normals = false});  // entries without normals
  EXPECT_THROW(dual_contouring(labels.grid, c, c.components[0], o, null_progress(), &no_normals),
               std::logic_error);
}

}  // namespace
}  // namespace segmesh
