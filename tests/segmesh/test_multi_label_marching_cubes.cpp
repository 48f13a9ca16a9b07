// Multi-label Marching Cubes: shared contacts, closed manifold outward shells per part, and the
// independent extraction's surfaces where a part meets only the background.
#include "segmesh/multi_label_marching_cubes.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/phantom.hpp"
#include "support/labelled_surface_checks.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

using Extracted = test::ExtractedLabels;
using test::expect_closed_shells;
using test::outer_volume;

Extracted extract(const LabelVolume& v, int connectivity = 26) {
  return test::extract_labels(v, connectivity,
                              [&](const Components& c, const std::vector<size_t>& parts) {
                                return multi_label_marching_cubes(v.grid, c, parts, connectivity);
                              });
}

TEST(MultiLabelMarchingCubes, TwoTouchingBoxesShareTheirContact) {
  const Extracted x = extract(test::two_touching_boxes());
  expect_closed_shells(x, "boxes");
  // The two shells' volumes add up to what the outer boundary encloses: the contact is shared.
  const double sum = enclosed_volume(x.shells[0]) + enclosed_volume(x.shells[1]);
  EXPECT_NEAR(sum, outer_volume(x.surface), 1e-9);
  // The contact is the plane x = 5.5 between the voxel centres' rim cells: 6 x 6 mm.
  const auto contacts = part_contacts(x.surface);
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_NEAR(contacts[0].area_mm2, 36.0, 1e-9);
}

TEST(MultiLabelMarchingCubes, APartAgainstTheBackgroundIsIndependentMarchingCubes) {
  // Under 26-connectivity no two parts share a cell, so every part's shell is exactly
  // independent Marching Cubes' (same triangle count, volume, Euler characteristic), the tube
  // cases included; under 6 and 18 the same holds for a label map of one component.
  std::mt19937 rng(7);
  for (int connectivity : {26, 26, 26}) {
    LabelVolume v = test::blank_labels({14, 13, 12});
    for (int64_t k = 2; k < 10; ++k)
      for (int64_t j = 2; j < 11; ++j)
        for (int64_t i = 2; i < 12; ++i) v.at(i, j, k) = rng() % 3 == 0 ? 1 : 0;
    const Extracted x = extract(v, connectivity);
    expect_closed_shells(x, "random, connectivity " + std::to_string(connectivity));
    for (size_t p = 0; p < x.parts.size(); ++p) {
      const Component& c = x.components.components[x.parts[p]];
      const TriMesh alone = marching_cubes(v.grid, x.components, c,
                                           {.connectivity = connectivity, .vertex_normals = false});
      const MeshMeasures a = measure_mesh(alone), b = measure_mesh(x.shells[p]);
      EXPECT_EQ(a.triangles, b.triangles) << "part " << p;
      EXPECT_EQ(a.euler, b.euler) << "part " << p;
      EXPECT_NEAR(a.volume_mm3, b.volume_mm3, 1e-6 * std::max(1.0, a.volume_mm3)) << "part " << p;
    }
  }
}

TEST(MultiLabelMarchingCubes, OneComponentIsIndependentMarchingCubesUnderEveryConnectivity) {
  for (int connectivity : {6, 18, 26}) {
    // The largest component of a random field: cavities, handles, diagonal contacts.
    std::mt19937 rng(3);
    LabelVolume v = test::blank_labels({12, 12, 12});
    for (int64_t k = 2; k < 10; ++k)
      for (int64_t j = 2; j < 10; ++j)
        for (int64_t i = 2; i < 10; ++i) v.at(i, j, k) = rng() % 2;
    const Components all = find_components(v, {.connectivity = connectivity});
    LabelVolume largest = test::blank_labels(v.grid.dims);
    for (const VoxelRun& r : all.runs_of(all.components[0]))
      for (int32_t i = r.x_begin; i < r.x_end; ++i) largest.at(i, r.y, r.z) = 1;
    v = largest;
    const Extracted x = extract(v, connectivity);
    ASSERT_EQ(x.parts.size(), 1u);
    const TriMesh alone = marching_cubes(v.grid, x.components, x.components.components[0],
                                         {.connectivity = connectivity, .vertex_normals = false});
    const MeshMeasures a = measure_mesh(alone), b = measure_mesh(x.shells[0]);
    EXPECT_EQ(a.triangles, b.triangles) << connectivity;
    EXPECT_EQ(a.euler, b.euler) << connectivity;
    EXPECT_EQ(a.shells, b.shells) << connectivity;
    EXPECT_NEAR(a.volume_mm3, b.volume_mm3, 1e-9 * a.volume_mm3) << connectivity;
  }
}

TEST(MultiLabelMarchingCubes, RandomMultiLabelFieldsGiveClosedManifoldShells) {
  // Many labels in random arrangements: every junction kind (three and four materials on a face,
  // diagonal pairs, cells of up to eight materials) must still close every part's shell.
  std::mt19937 rng(11);
  for (int round = 0; round < 12; ++round) {
    const int labels = 2 + round % 5;
    for (int connectivity : {6, 18, 26}) {
      const Extracted x = extract(test::random_labels(rng, labels), connectivity);
      expect_closed_shells(x, "round " + std::to_string(round) + " connectivity " +
                                  std::to_string(connectivity));
      // The parts' volumes add up to the volume inside the outer boundary: every contact is
      // shared (once from each side, with opposite signs), none is doubled or left open.
      double parts = 0;
      for (const TriMesh& s : x.shells) parts += enclosed_volume(s);
      const double together = outer_volume(x.surface);
      EXPECT_NEAR(parts, together, 1e-9 * together) << "round " << round;
    }
  }
}

TEST(MultiLabelMarchingCubes, ThePhantomsImplantSharesTheBoneSurface) {
  const LabelVolume v = make_phantom({.size = {160, 160, 64}, .spacing = {0.6, 0.6, 6.0}});
  const Extracted x = extract(v);
  expect_closed_shells(x, "phantom");
  // Every triangle the implant shares with bone is one triangle of the surface: both shells
  // hold it, with opposite windings, on the same vertex positions.
  size_t contact = 0;
  for (const auto& s : x.surface.sides) {
    const int32_t in = s[0] ? x.components.components[s[0] - 1].label : 0;
    const int32_t out = s[1] ? x.components.components[s[1] - 1].label : 0;
    if ((in == 1 && out == 2) || (in == 2 && out == 1)) ++contact;
  }
  EXPECT_GT(contact, 100u);
  EXPECT_FALSE(part_contacts(x.surface).empty());
}

}  // namespace
}  // namespace segmesh
