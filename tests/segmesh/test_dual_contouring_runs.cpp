// Dual Contouring of a label part from its runs (cells from run_scan.hpp) against Dual Contouring
// of the part's mask: the same mesh, for every connectivity and both normal operators, on random
// label maps whose parts touch the volume border; identical for any thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

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

TEST(DualContouringRuns, IdenticalForAnyThreadCount) {
  const LabelVolume labels = random_labels({50, 40, 36}, 0.55, 13);
  const Components c = find_components(labels, {});
  TriMesh one, many;
  tbb::task_arena(1).execute([&] { one = dual_contouring(labels.grid, c, c.components[0], {}); });
  tbb::task_arena(4).execute([&] { many = dual_contouring(labels.grid, c, c.components[0], {}); });
  ASSERT_GT(one.triangle_count(), 10000u);
  EXPECT_TRUE(identical(one, many));
}

}  // namespace
}  // namespace segmesh
