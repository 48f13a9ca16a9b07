// The part table's contacts and the switch between conforming and independent surfaces, through
// the viewer's own path: panel settings -> meshing_request -> run_load (build_scene,
// measure_scene) -> finish_load -> part_table.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <set>
#include <string>

#include "segmesh/phantom.hpp"
#include "segmesh_viewer/load_job.hpp"
#include "segmesh_viewer/meshing_settings.hpp"
#include "segmesh_viewer/part_table.hpp"
#include "support/test_fields.hpp"

namespace segmesh::viewer {
namespace {

// Two boxes side by side along x on an anisotropic grid: label 1 on voxels i 2..11, label 2 on
// i 12..21, both on j 2..17 and k 2..13. Marching Cubes puts their contact on the plane between
// the voxel centres i = 11 and 12, over the rim cells' midpoints: 16 x 12 voxels of 0.8 x 1.2 mm.
constexpr double kContactArea = 16 * 0.8 * 12 * 1.2;

std::shared_ptr<const Image> two_touching_boxes() {
  LabelVolume v = test::blank_labels({24, 20, 16}, {0.5, 0.8, 1.2});
  test::fill_box(v, {2, 2, 2}, {12, 18, 14}, 1);
  test::fill_box(v, {12, 2, 2}, {22, 18, 14}, 2);
  return std::make_shared<const Image>(test::label_image(std::move(v), "boxes.nii.gz"));
}

// The viewer's state after meshing `image` with the panel's `settings`.
ViewerState meshed(const std::shared_ptr<const Image>& image, const MeshingSettings& settings) {
  LoadResult result = run_load({{}, image, meshing_request(settings)});
  ViewerState state;
  finish_load(state, {LoadOutcome::Kind::loaded, std::move(result), "meshed"});
  return state;
}

// Vertices of part a's mesh at exactly the position of one of part b's.
size_t shared_positions(const TriMesh& a, const TriMesh& b) {
  std::set<std::array<float, 3>> in_b;
  for (const Vec3f& p : b.positions) in_b.insert({p.x, p.y, p.z});
  size_t n = 0;
  for (const Vec3f& p : a.positions) n += in_b.count({p.x, p.y, p.z});
  return n;
}

// "label2_1: 184.3 mm2, gap 0.000 mm" -> 184.3, checking the rest of the line.
double area_in(const std::string& line, const std::string& other) {
  const std::string head = other + ": ";
  EXPECT_EQ(line.rfind(head, 0), 0u) << line;
  const size_t end = line.find(" mm2, gap ");
  EXPECT_NE(end, std::string::npos) << line;
  if (line.rfind(head, 0) != 0 || end == std::string::npos) return NAN;
  return std::stod(line.substr(head.size(), end - head.size()));
}

// The panel's triangle budget reaches build_scene: the two boxes, decimated to a budget, keep
// their contact and stay within it, and the panel's count line says so.
TEST(PartTable, ATriangleBudgetFromThePanelDecimatesTheScene) {
  const ViewerState full = meshed(two_touching_boxes(), MeshingSettings{});
  size_t before = 0;
  for (const Part& p : full.scene.parts) before += p.mesh.triangle_count();
  MeshingSettings settings;
  settings.max_triangles = 400;
  const ViewerState state = meshed(two_touching_boxes(), settings);
  ASSERT_EQ(state.scene.parts.size(), 2u);
  size_t after = 0;
  for (const Part& p : state.scene.parts) after += p.mesh.triangle_count();
  EXPECT_GT(before, 2 * after);
  EXPECT_LE(after, 400u);
  EXPECT_EQ(triangle_count_text(state.scene), std::to_string(after) + " triangles in 2 parts");
  const std::vector<PartTableRow> rows = part_table(state.scene, state.stats);
  ASSERT_EQ(rows[0].contacts.size(), 1u);
  EXPECT_NEAR(area_in(rows[0].contacts[0], "label2_1"), kContactArea, 0.01 * kContactArea);
}

TEST(PartTable, TwoTouchingBoxesListTheirContactWithItsArea) {
  const ViewerState state = meshed(two_touching_boxes(), MeshingSettings{});
  ASSERT_EQ(state.scene.parts.size(), 2u);
  EXPECT_TRUE(state.scene.surface.has_value());
  EXPECT_EQ(state.surfaces, "conforming surfaces: touching parts share their contacts");
  const std::vector<PartTableRow> rows = part_table(state.scene, state.stats);
  ASSERT_EQ(rows.size(), 2u);
  const std::string& a = state.scene.parts[0].name;
  const std::string& b = state.scene.parts[1].name;
  EXPECT_EQ(rows[0].cells[0], a);
  // Each box lists the other, once, with the contact's area and no gap. (Smoothing moves a
  // junction curve's vertices only along the curve, here straight lines between fixed corners,
  // so the contact stays the rectangle.)
  ASSERT_EQ(rows[0].contacts.size(), 1u);
  ASSERT_EQ(rows[1].contacts.size(), 1u);
  EXPECT_NEAR(area_in(rows[0].contacts[0], b), kContactArea, 0.01 * kContactArea) << rows[0].contacts[0];
  EXPECT_NEAR(area_in(rows[1].contacts[0], a), kContactArea, 0.01 * kContactArea) << rows[1].contacts[0];
  EXPECT_TRUE(rows[0].contacts[0].ends_with(" mm2, gap 0.000 mm")) << rows[0].contacts[0];
  // The line is the measured contact's, seen from either side.
  ASSERT_EQ(state.stats[0].contacts.size(), 1u);
  EXPECT_EQ(state.stats[0].contacts[0].other, 1u);
  EXPECT_EQ(state.stats[1].contacts[0].other, 0u);
  EXPECT_EQ(state.stats[0].contacts[0].area_mm2, state.stats[1].contacts[0].area_mm2);
  EXPECT_LT(state.stats[0].contacts[0].max_gap_mm, 1e-4);
}

TEST(PartTable, IndependentSurfacesListNoContacts) {
  const std::shared_ptr<const Image> image = two_touching_boxes();
  const ViewerState conforming = meshed(image, MeshingSettings{});
  MeshingSettings settings;
  settings.surfaces = Surfaces::independent;
  const ViewerState independent = meshed(image, settings);
  ASSERT_EQ(independent.scene.parts.size(), 2u);
  EXPECT_FALSE(independent.scene.conforming);
  EXPECT_FALSE(independent.scene.surface.has_value());
  EXPECT_EQ(independent.surfaces, "independent surfaces: touching parts each have their own surface");
  for (const PartTableRow& row : part_table(independent.scene, independent.stats)) {
    EXPECT_TRUE(row.contacts.empty()) << row.cells[0];
    EXPECT_FALSE(row.cells[1].empty());  // the rest of the row is there
  }
  // Meshed one by one: smoothing moved each box's side of the contact on its own, so the two
  // shells no longer share the contact's vertices as the conforming shells do.
  const size_t shared = shared_positions(conforming.scene.parts[0].mesh, conforming.scene.parts[1].mesh);
  EXPECT_GT(shared, 100u);
  EXPECT_LT(shared_positions(independent.scene.parts[0].mesh, independent.scene.parts[1].mesh),
            shared / 10);
}

TEST(PartTable, AutomaticSurfacesWithDualContouringAreConforming) {
  MeshingSettings settings;
  settings.method = Method::dual_contouring;
  const ViewerState state = meshed(two_touching_boxes(), settings);
  EXPECT_TRUE(state.scene.conforming);
  EXPECT_TRUE(state.scene.surface.has_value());
  EXPECT_FALSE(surfaces_note(meshing_request(settings)).has_value());
  for (const PartTableRow& row : part_table(state.scene, state.stats)) {
    ASSERT_EQ(row.contacts.size(), 1u);
    EXPECT_TRUE(row.contacts[0].ends_with(" mm2, gap 0.000 mm")) << row.contacts[0];
  }
}

TEST(PartTable, PartsThatTouchNowhereHaveNoContacts) {
  // Two boxes four voxels apart along x.
  LabelVolume v = test::blank_labels({20, 8, 8});
  test::fill_box(v, {2, 2, 2}, {8, 6, 6}, 1);
  test::fill_box(v, {12, 2, 2}, {18, 6, 6}, 2);
  const ViewerState state =
      meshed(std::make_shared<const Image>(test::label_image(std::move(v))), MeshingSettings{});
  ASSERT_EQ(state.scene.parts.size(), 2u);
  EXPECT_TRUE(state.scene.conforming);
  EXPECT_EQ(state.surfaces, "conforming surfaces: no parts touch, so each part was meshed on its own");
  for (const PartTableRow& row : part_table(state.scene, state.stats)) EXPECT_TRUE(row.contacts.empty());
}

// The phantom: its implant bridges the fracture, so it touches both bone fragments; every contact
// is listed under both its parts with the measured numbers, a plausible area (more than nothing,
// less than either part's whole surface) and no gap.
TEST(PartTable, ThePhantomListsItsImplantsContactsWithTheBone) {
  auto image = std::make_shared<const Image>(
      test::label_image(make_phantom({{160, 160, 102}, {0.63, 0.63, 4.0}}), "phantom.nii.gz"));
  const ViewerState state = meshed(image, MeshingSettings{});
  const std::vector<PartTableRow> rows = part_table(state.scene, state.stats);
  size_t listed = 0;
  std::set<size_t> bones_under_implants;
  for (size_t p = 0; p < rows.size(); ++p) {
    ASSERT_EQ(rows[p].contacts.size(), state.stats[p].contacts.size());
    for (size_t c = 0; c < rows[p].contacts.size(); ++c) {
      const ContactStats& contact = state.stats[p].contacts[c];
      const Part& other = state.scene.parts[contact.other];
      const double area = area_in(rows[p].contacts[c], other.name);
      EXPECT_NEAR(area, contact.area_mm2, 0.05 + 1e-9 * area);
      EXPECT_GT(area, 1.0) << rows[p].contacts[c];
      EXPECT_LT(area, std::min(state.stats[p].area_mm2, state.stats[contact.other].area_mm2));
      EXPECT_LT(contact.max_gap_mm, 1e-3);
      // The same contact under the other part.
      bool mirrored = false;
      for (const ContactStats& back : state.stats[contact.other].contacts) {
        mirrored = mirrored || (back.other == p && back.area_mm2 == contact.area_mm2);
      }
      EXPECT_TRUE(mirrored) << rows[p].contacts[c];
      if (state.scene.parts[p].role == Role::implant && other.role == Role::bone) {
        bones_under_implants.insert(contact.other);
      }
      ++listed;
    }
  }
  EXPECT_EQ(bones_under_implants.size(), 2u);  // both fragments
  EXPECT_EQ(listed % 2, 0u);  // each contact twice
}

TEST(PartTable, AMeshFileHasNoSurfacesLine) {
  ViewerState state;
  state.surfaces = "conforming surfaces: touching parts share their contacts";
  LoadResult mesh;
  mesh.kind = InputKind::mesh;
  mesh.scene.parts.resize(1);
  finish_load(state, {LoadOutcome::Kind::loaded, std::move(mesh), "read"});
  EXPECT_TRUE(state.surfaces.empty());
  EXPECT_TRUE(part_table(state.scene, state.stats)[0].contacts.empty());
}

}  // namespace
}  // namespace segmesh::viewer
