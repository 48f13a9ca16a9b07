// Multi-label Marching Cubes: shared contacts, closed manifold outward shells per part, and the
// independent extraction's surfaces where a part meets only the background.
#include "segmesh/multi_label_marching_cubes.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>

#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/phantom.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

struct Extracted {
  Components components;
  std::vector<size_t> parts;
  LabelledSurface surface;
  std::vector<TriMesh> shells;
};

Extracted extract(const LabelVolume& v, int connectivity = 26) {
  Extracted x;
  x.components = find_components(v, {.connectivity = connectivity});
  for (size_t c = 0; c < x.components.components.size(); ++c) x.parts.push_back(c);
  x.surface = multi_label_marching_cubes(v.grid, x.components, x.parts, connectivity);
  x.shells = part_shells(x.surface);
  return x;
}

// The volume inside the surface's outer boundary (its triangles against the background): what the
// parts' shells enclose together when every contact is shared (each counts once from each side).
double outer_volume(const LabelledSurface& surface) {
  TriMesh outer;
  outer.positions = surface.mesh.positions;
  for (size_t t = 0; t < surface.sides.size(); ++t) {
    const auto [in, out] = surface.sides[t];
    if ((in == 0) == (out == 0)) continue;
    const uint32_t* i = &surface.mesh.indices[3 * t];
    if (out == 0) {
      outer.indices.insert(outer.indices.end(), {i[0], i[1], i[2]});
    } else {
      outer.indices.insert(outer.indices.end(), {i[0], i[2], i[1]});
    }
  }
  return enclosed_volume(outer);
}

void expect_closed_shells(const Extracted& x, const std::string& what) {
  ASSERT_EQ(x.shells.size(), x.parts.size()) << what;
  for (size_t p = 0; p < x.shells.size(); ++p) {
    const MeshMeasures m = measure_mesh(x.shells[p]);
    EXPECT_TRUE(m.closed()) << what << " part " << p << ": boundary " << m.boundary_edges
                            << ", non-manifold " << m.nonmanifold_edges << ", winding "
                            << m.winding_errors;
    EXPECT_EQ(m.nonmanifold_vertices, 0) << what << " part " << p;
    EXPECT_GT(m.volume_mm3, 0) << what << " part " << p;
  }
}

TEST(MultiLabelMarchingCubes, TwoTouchingBoxesShareTheirContact) {
  LabelVolume v = test::blank_labels({12, 10, 10});
  for (int k = 2; k < 8; ++k)
    for (int j = 2; j < 8; ++j)
      for (int i = 2; i < 10; ++i) v.at(i, j, k) = i < 6 ? 1 : 2;
  const Extracted x = extract(v);
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
      LabelVolume v = test::blank_labels({11, 10, 9});
      for (int64_t k = 1; k < 8; ++k)
        for (int64_t j = 1; j < 9; ++j)
          for (int64_t i = 1; i < 10; ++i) v.at(i, j, k) = int32_t(rng() % (labels + 1));
      const Extracted x = extract(v, connectivity);
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
