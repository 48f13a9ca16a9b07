// Multi-label Dual Contouring: shared contacts, closed manifold outward shells per part (random
// label fields, a checkerboard, three materials at a junction, the phantom), and independent Dual
// Contouring's surfaces where a part meets only the background.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "segmesh/dual_contouring.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/multi_label_dual_contouring.hpp"
#include "segmesh/multi_label_marching_cubes.hpp"
#include "segmesh/phantom.hpp"
#include "support/labelled_surface_checks.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

using Extracted = test::ExtractedLabels;
using test::expect_closed_shells;

Extracted extract(const LabelVolume& v, int connectivity = 26) {
  return test::extract_labels(
      v, connectivity, [&](const Components& c, const std::vector<size_t>& parts) {
        return multi_label_dual_contouring(v.grid, c, parts, {.connectivity = connectivity});
      });
}

// The parts' volumes add up to the volume inside the outer boundary: every contact is shared
// (once from each side, with opposite signs), none is doubled or left open.
void expect_shared_contacts(const Extracted& x, const std::string& what) {
  double parts = 0;
  for (const TriMesh& s : x.shells) parts += enclosed_volume(s);
  const double together = test::outer_volume(x.surface);
  EXPECT_NEAR(parts, together, 1e-6 * together) << what;
}

TEST(MultiLabelDualContouring, TwoTouchingBoxesShareTheirContact) {
  const Extracted x = extract(test::two_touching_boxes());
  expect_closed_shells(x, "boxes");
  expect_shared_contacts(x, "boxes");
  const auto contacts = part_contacts(x.surface);
  ASSERT_EQ(contacts.size(), 1u);
  // The contact lies in the plane x = 5.5 and spans the boxes' cross-section, 6 x 6 mm, less
  // the rim the vertices keep inside their cells.
  EXPECT_GT(contacts[0].area_mm2, 30.0);
  EXPECT_LT(contacts[0].area_mm2, 36.0);
  for (const TriMesh& s : x.shells) {
    const MeshMeasures m = measure_mesh(s);
    EXPECT_EQ(m.euler, 2);
    EXPECT_EQ(m.shells, 1);
  }
}

TEST(MultiLabelDualContouring, APartAgainstTheBackgroundIsIndependentDualContouring) {
  // Under 26-connectivity no two parts share a cell, so every part's shell is independent Dual
  // Contouring's: same triangle count and Euler characteristic, volume within rounding.
  std::mt19937 rng(7);
  for (int round = 0; round < 3; ++round) {
    LabelVolume v = test::blank_labels({14, 13, 12});
    for (int64_t k = 2; k < 10; ++k)
      for (int64_t j = 2; j < 11; ++j)
        for (int64_t i = 2; i < 12; ++i) v.at(i, j, k) = rng() % 3 == 0 ? 1 : 0;
    const Extracted x = extract(v);
    expect_closed_shells(x, "random, round " + std::to_string(round));
    for (size_t p = 0; p < x.parts.size(); ++p) {
      const Component& c = x.components.components[x.parts[p]];
      const TriMesh alone = dual_contouring(v.grid, x.components, c, {.vertex_normals = false});
      const MeshMeasures a = measure_mesh(alone), b = measure_mesh(x.shells[p]);
      EXPECT_EQ(a.triangles, b.triangles) << "part " << p;
      EXPECT_EQ(a.euler, b.euler) << "part " << p;
      EXPECT_NEAR(a.volume_mm3, b.volume_mm3, 1e-5 * std::max(1.0, a.volume_mm3)) << "part " << p;
    }
  }
}

TEST(MultiLabelDualContouring, RandomMultiLabelFieldsGiveClosedManifoldShells) {
  std::mt19937 rng(11);
  for (int round = 0; round < 24; ++round) {
    const int labels = 2 + round % 5;
    for (int connectivity : {6, 18, 26}) {
      const Extracted x = extract(test::random_labels(rng, labels), connectivity);
      const std::string what =
          "round " + std::to_string(round) + " connectivity " + std::to_string(connectivity);
      expect_closed_shells(x, what);
      expect_shared_contacts(x, what);
    }
  }
}

TEST(MultiLabelDualContouring, CheckerboardsGiveClosedManifoldShells) {
  // Every face of a voxel checkerboard is ambiguous and every cell a junction of its materials:
  // the pieces of neighbouring junction cells hold both segments of a face, so two sheets of one
  // part share an edge, which part_shells parts (labelled_surface.hpp). Two and three materials,
  // single voxels and 2 x 2 x 2 blocks, under every connectivity.
  for (int materials : {2, 3})
    for (int block : {1, 2})
      for (int connectivity : {6, 18, 26}) {
        LabelVolume v = test::blank_labels({14, 13, 12});
        for (int64_t k = 2; k < 10; ++k)
          for (int64_t j = 2; j < 11; ++j)
            for (int64_t i = 2; i < 12; ++i)
              v.at(i, j, k) = int32_t(1 + (i / block + j / block + k / block) % materials);
        const Extracted x = extract(v, connectivity);
        const std::string what = std::to_string(materials) + " materials, block " +
                                 std::to_string(block) + ", connectivity " +
                                 std::to_string(connectivity);
        ASSERT_GE(x.parts.size(), 2u) << what;
        EXPECT_FALSE(x.surface.junction_vertices.empty()) << what;
        expect_closed_shells(x, what);
        expect_shared_contacts(x, what);
      }
}

TEST(MultiLabelDualContouring, ThreeMaterialsMeetAlongAJunctionCurve) {
  // A block cut into three sectors around the line x = y = 7.5: each sector is a ball
  // topologically (Euler characteristic 2, one shell); the three contacts meet the background
  // and each other along the junction curve, whose vertices are shared by all three shells.
  LabelVolume v = test::blank_labels({16, 16, 12}, {0.5, 0.6, 0.8});
  for (int64_t k = 2; k < 10; ++k)
    for (int64_t j = 2; j < 14; ++j)
      for (int64_t i = 2; i < 14; ++i) {
        const double a = std::atan2(double(j) - 7.5, double(i) - 7.5);
        v.at(i, j, k) = a < -1.0 ? 1 : a < 1.2 ? 2 : 3;
      }
  const Extracted x = extract(v);
  ASSERT_EQ(x.parts.size(), 3u);
  expect_closed_shells(x, "sectors");
  expect_shared_contacts(x, "sectors");
  for (const TriMesh& s : x.shells) {
    const MeshMeasures m = measure_mesh(s);
    EXPECT_EQ(m.euler, 2);
    EXPECT_EQ(m.shells, 1);
  }
  EXPECT_EQ(part_contacts(x.surface).size(), 3u);
  EXPECT_FALSE(x.surface.junction_vertices.empty());
  // Every vertex lies inside the parts' common box grown by the background margin, and the
  // three volumes add up to the block's voxel volume to within the rounded rim (2 %).
  double total = 0;
  for (const TriMesh& s : x.shells) total += enclosed_volume(s);
  const double voxels = 12.0 * 12.0 * 8.0 * v.grid.voxel_volume();
  EXPECT_NEAR(total, voxels, 0.02 * voxels);
}

TEST(MultiLabelDualContouring, ThePhantomsPartsAreClosedAndShareTheirContacts) {
  const LabelVolume v = make_phantom({.size = {160, 160, 64}, .spacing = {0.6, 0.6, 6.0}});
  const Extracted x = extract(v);
  expect_closed_shells(x, "phantom");
  expect_shared_contacts(x, "phantom");
  size_t contact = 0;
  for (const auto& s : x.surface.sides) contact += s[0] != 0 && s[1] != 0;
  EXPECT_GT(contact, 100u);
  // Each part has the shells multi-label Marching Cubes gives it (the same face rule, each cell's
  // pieces contracted; where the implant is a voxel or two thick at this coarse size, the bone wins
  // ambiguous faces and a screw comes apart into several shells, on both), and its genus but where
  // two sheets of it share an edge whose ends both see them as one fan (labelled_surface.hpp):
  // there the shell is parted across the face rule's join, one handle fewer (measured: one, on a
  // bone).
  const std::vector<TriMesh> mc =
      part_shells(multi_label_marching_cubes(v.grid, x.components, x.parts, 26));
  int handles_parted = 0;
  for (size_t p = 0; p < x.parts.size(); ++p) {
    const MeshMeasures a = measure_mesh(mc[p]), b = measure_mesh(x.shells[p]);
    EXPECT_EQ(a.shells, b.shells) << "part " << p;
    EXPECT_GE(b.euler, a.euler) << "part " << p;
    handles_parted += (b.euler - a.euler) / 2;
  }
  EXPECT_LE(handles_parted, 1);
}

}  // namespace
}  // namespace segmesh
