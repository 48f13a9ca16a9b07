// Conforming surfaces (--surfaces conforming): the parts of a label map extracted as one surface
// and smoothed jointly (joint_smoothing.hpp) through build_scene. Contacts stay exact through
// smoothing, every part's shell stays closed, manifold and outward, and the volumes stay those of
// the independent path.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>
#include <unordered_map>

#include "segmesh/detail/fold_repair.hpp"
#include "segmesh/joint_smoothing.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/multi_label_dual_contouring.hpp"
#include "segmesh/multi_label_marching_cubes.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene_measures.hpp"
#include "support/labelled_surface_checks.hpp"
#include "support/mesh_crossings.hpp"
#include "support/sound_parts.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

// A 40 x 40 x 40 voxel bone block (label 1, 0.5 mm voxels) with a screw (label 2): a shaft of
// radius 3 voxels along z through most of the block and a head above it, in the background.
LabelVolume screw_in_block() {
  LabelVolume v = test::blank_labels({48, 48, 56}, {0.5, 0.5, 0.5});
  for (int64_t k = 0; k < 56; ++k)
    for (int64_t j = 0; j < 48; ++j)
      for (int64_t i = 0; i < 48; ++i) {
        const double r = std::hypot(double(i) - 23.5, double(j) - 23.5);
        uint8_t label = 0;
        if (i >= 4 && i < 44 && j >= 4 && j < 44 && k >= 4 && k < 44) label = 1;
        if (k >= 10 && k < 48 && r < 3.2) label = 2;  // the shaft
        if (k >= 44 && k < 48 && r < 6.2) label = 2;  // the head, on the block
        v.at(i, j, k) = label;
      }
  return v;
}

// The vertices of the shared surface on a contact between two parts (not the background).
std::vector<Vec3d> contact_vertices(const LabelledSurface& s) {
  std::vector<char> on(s.mesh.positions.size(), 0);
  for (size_t t = 0; t < s.sides.size(); ++t) {
    if (s.sides[t][0] == 0 || s.sides[t][1] == 0) continue;
    for (int k = 0; k < 3; ++k) on[s.mesh.indices[3 * t + size_t(k)]] = 1;
  }
  std::vector<Vec3d> out;
  for (size_t v = 0; v < on.size(); ++v)
    if (on[v]) out.push_back(to_double(s.mesh.positions[v]));
  return out;
}

TEST(JointSmoothing, AScrewStaysInContactWithItsBlockThroughEverySmoothing) {
  const Image image = test::label_image(screw_in_block());
  for (Method extractor : {Method::marching_cubes, Method::dual_contouring}) {
    for (SmoothMethod method :
         {SmoothMethod::sinc, SmoothMethod::hc, SmoothMethod::taubin, SmoothMethod::laplacian}) {
      SCOPED_TRACE(method_name(extractor));
      MeshingOptions o;
      o.method = extractor;
      o.surfaces = Surfaces::conforming;
      o.smooth = default_smoothing();
      o.smooth.method = method;
      const Scene scene = build_scene(image, o);
      ASSERT_EQ(scene.parts.size(), 2u);
      ASSERT_TRUE(scene.surface.has_value());
      test::expect_sound_shells(scene);
      const std::vector<Vec3d> contact = contact_vertices(*scene.surface);
      ASSERT_GT(contact.size(), 100u);
      const MeshDistance block(scene.parts[0].mesh), screw(scene.parts[1].mesh);
      double worst = 0;
      for (const Vec3d& p : contact)
        worst = std::max({worst, block.distance(p), screw.distance(p)});
      EXPECT_LT(worst, 1e-4) << smooth_method_name(method);

      // The independent path on the same map leaves the two sides apart.
      o.surfaces = Surfaces::independent;
      const Scene apart = build_scene(image, o);
      const MeshDistance block_apart(apart.parts[0].mesh);
      std::vector<double> gaps;
      for (const Vec3f& p : apart.parts[1].mesh.positions) {
        const double d = block_apart.distance(to_double(p));
        if (d < 0.5) gaps.push_back(d);  // the screw's side of the contact
      }
      ASSERT_FALSE(gaps.empty());
      EXPECT_GT(percentile(gaps, 0.9), 0.01) << smooth_method_name(method);
    }
  }
}

TEST(JointSmoothing, ThePhantomKeepsItsContactsAndVolumes) {
  const Image image =
      test::label_image(make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4}}));
  for (Method extractor : {Method::marching_cubes, Method::dual_contouring}) {
    SCOPED_TRACE(method_name(extractor));
    MeshingOptions o;
    o.method = extractor;
    o.surfaces = Surfaces::conforming;
    const Scene conforming = build_scene(image, o);
    o.surfaces = Surfaces::independent;
    const Scene independent = build_scene(image, o);
    ASSERT_EQ(conforming.parts.size(), independent.parts.size());
    test::expect_sound_shells(conforming);
    for (size_t p = 0; p < conforming.parts.size(); ++p) {
      EXPECT_EQ(conforming.parts[p].name, independent.parts[p].name);
      const double a = enclosed_volume(conforming.parts[p].mesh);
      const double b = enclosed_volume(independent.parts[p].mesh);
      // The same topology as on its own: one closed surface of the same genus.
      EXPECT_EQ(measure_mesh(conforming.parts[p].mesh).euler,
                measure_mesh(independent.parts[p].mesh).euler)
          << conforming.parts[p].name;
      // Bulky parts (the bones and the plate) keep their volume to 1 % as on their own.
      if (conforming.parts[p].voxels > 10000) {
        EXPECT_NEAR(a, b, 0.01 * b) << conforming.parts[p].name;
      }
    }
    // Every implant vertex on the bone contact is on both surfaces after the default smoothing.
    const std::vector<Vec3d> contact = contact_vertices(*conforming.surface);
    ASSERT_GT(contact.size(), 1000u);
    std::vector<MeshDistance> shells;
    for (const Part& part : conforming.parts) shells.emplace_back(part.mesh);
    size_t on_two = 0;
    for (const Vec3d& p : contact) {
      int near = 0;
      for (const MeshDistance& s : shells) near += s.distance(p) < 1e-4;
      on_two += near >= 2;
    }
    EXPECT_EQ(on_two, contact.size());
    // No implant triangle crosses a bone's. Smoothing alone folds the surface where the two
    // fragments, the plate and the background meet (measured: 72 and 70 edge crossings with the
    // two fragments; 3306 and 3318 with independent surfaces); the fold repair undoes it.
    const SceneMeasures m = measure_scene(conforming, {});
    ASSERT_EQ(m.contacts.size(), 8u);  // the plate on both fragments, the six screws
    for (const ContactMeasures& c : m.contacts) {
      const Part& a = conforming.parts[c.a];
      const Part& b = conforming.parts[c.b];
      EXPECT_EQ(test::crossings(a.mesh, b.mesh), 0u) << a.name << " " << b.name;
      if (b.label == 2 && b.component == 1) {  // the plate: the independent surfaces do cross
        EXPECT_GT(test::crossings(independent.parts[c.a].mesh, independent.parts[c.b].mesh), 1000u)
            << a.name << " " << b.name;
      }
    }
  }
}

// The contact seen from both shells: no triangle of one part crosses the other's, and at a
// contact vertex inside the contact each part's normal points out of that part, so the two are
// opposite.
TEST(JointSmoothing, TouchingPartsNeitherCrossNorShareNormals) {
  const Image image = test::label_image(screw_in_block());
  for (Method extractor : {Method::marching_cubes, Method::dual_contouring}) {
    SCOPED_TRACE(method_name(extractor));
    MeshingOptions o;
    o.method = extractor;
    o.surfaces = Surfaces::conforming;
    const Scene scene = build_scene(image, o);
    ASSERT_EQ(scene.parts.size(), 2u);
    EXPECT_EQ(test::crossings(scene.parts[0].mesh, scene.parts[1].mesh), 0u);
    // The independent surfaces of the same map do cross (smoothing moved the sides apart and into
    // each other): the check can fail.
    o.surfaces = Surfaces::independent;
    const Scene apart = build_scene(image, o);
    EXPECT_GT(test::crossings(apart.parts[0].mesh, apart.parts[1].mesh), 0u);

    // Normals at the vertices both shells have, by position (the contact's vertices).
    std::map<std::array<float, 3>, Vec3f> block_normal;
    const TriMesh& block = scene.parts[0].mesh;
    for (size_t v = 0; v < block.positions.size(); ++v) {
      const Vec3f p = block.positions[v];
      block_normal[{p.x, p.y, p.z}] = block.normals[v];
    }
    std::vector<double> dots;
    const TriMesh& screw = scene.parts[1].mesh;
    for (size_t v = 0; v < screw.positions.size(); ++v) {
      const Vec3f p = screw.positions[v];
      const auto it = block_normal.find({p.x, p.y, p.z});
      if (it != block_normal.end())
        dots.push_back(dot(to_double(it->second), to_double(screw.normals[v])));
    }
    ASSERT_GT(dots.size(), 100u);
    EXPECT_LT(percentile(dots, 0.5), -0.99);  // inside the contact: opposite
  }
}

// The report's contacts: every pair of touching parts with its area, and the largest distance
// from a contact vertex to either shell as written: 0 when the two sides are one surface, the
// shift when one shell is moved off it.
TEST(JointSmoothing, ContactsAreMeasuredOnTheShellsAsWritten) {
  const Image image = test::label_image(screw_in_block());
  MeshingOptions o;
  o.surfaces = Surfaces::conforming;
  Scene scene = build_scene(image, o);
  SceneMeasures m = measure_scene(scene, {});
  ASSERT_EQ(m.contacts.size(), 1u);
  EXPECT_EQ(m.contacts[0].a, 0u);
  EXPECT_EQ(m.contacts[0].b, 1u);
  // The shaft's side and bottom inside the block: 2 pi r h + pi r^2 with r about 1.6 mm, h 17 mm.
  EXPECT_GT(m.contacts[0].area_mm2, 150);
  EXPECT_LT(m.contacts[0].area_mm2, 230);
  EXPECT_LT(m.contacts[0].max_gap_mm, 1e-4);
  EXPECT_TRUE(measure_scene(scene, {.contacts = false}).contacts.empty());  // not asked for
  for (Vec3f& p : scene.parts[1].mesh.positions) p.x += 0.1f;
  m = measure_scene(scene, {});
  EXPECT_NEAR(m.contacts[0].max_gap_mm, 0.1, 0.02);

  o.surfaces = Surfaces::independent;
  EXPECT_TRUE(measure_scene(build_scene(image, o), {}).contacts.empty());
}

// Parts that touch nowhere: build_scene meshes them one by one (no labelled surface), and that
// is what the one surface would give too: the same shells, smoothed the same way.
TEST(JointSmoothing, PartsThatDoNotTouchGiveTheIndependentSurfaces) {
  LabelVolume v = test::blank_labels({40, 24, 24}, {0.5, 0.5, 1.0});
  for (int64_t k = 4; k < 20; ++k)
    for (int64_t j = 4; j < 20; ++j)
      for (int64_t i = 3; i < 36; ++i) {
        const double r = std::hypot(double(j) - 11.5, double(k) - 11.5);
        if (i < 18 && r < 7) v.at(i, j, k) = 1;                          // a rod
        if (i >= 20 && r < 5 + 0.1 * double(i - 20)) v.at(i, j, k) = 2;  // a cone, 1 voxel apart
      }
  const Image image = test::label_image(v);
  MeshingOptions o;
  o.surfaces = Surfaces::conforming;
  const Scene scene = build_scene(image, o);
  EXPECT_TRUE(scene.conforming);
  EXPECT_FALSE(scene.surface.has_value());
  o.surfaces = Surfaces::independent;
  const Scene independent = build_scene(image, o);

  const Components c = find_components(v, {.connectivity = 26});
  ASSERT_EQ(c.components.size(), 2u);
  ASSERT_FALSE(components_touch(c, {0, 1}));
  const std::vector<size_t> both = {0, 1};
  LabelledSurface one = multi_label_marching_cubes(v.grid, c, both, 26);
  smooth_jointly(one, default_smoothing());
  const std::vector<TriMesh> shells = part_shells(one);
  ASSERT_EQ(shells.size(), 2u);
  for (size_t p = 0; p < 2; ++p) {
    EXPECT_EQ(scene.parts[p].mesh.triangle_count(), shells[p].triangle_count());
    EXPECT_EQ(independent.parts[p].mesh.indices, scene.parts[p].mesh.indices);
    const double a = enclosed_volume(shells[p]), b = enclosed_volume(scene.parts[p].mesh);
    EXPECT_NEAR(a, b, 1e-6 * b) << p;
    EXPECT_LT(mesh_deviation(shells[p], scene.parts[p].mesh).hausdorff, 1e-4) << p;
  }
}

// Both windings of a contact are one interface (multi-label Marching Cubes mixes (1, 2) and
// (2, 1) along one contact, and (p, 0) with (0, p)): a vertex where the winding changes is
// smoothed like its neighbours. Counted as two interfaces, such vertices stayed where they were
// extracted: on the test-size phantom they left triangles with radii ratios near 1e-8 and
// thousands of contact vertices unmoved.
TEST(JointSmoothing, ContactVerticesWhereTheWindingChangesAreSmoothed) {
  const Image image =
      test::label_image(make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4}}));
  MeshingOptions o;
  o.surfaces = Surfaces::conforming;
  o.smooth.method = SmoothMethod::none;
  const Scene raw = build_scene(image, o);
  o.smooth = default_smoothing();
  const Scene smoothed = build_scene(image, o);
  ASSERT_TRUE(raw.surface && smoothed.surface);
  const LabelledSurface& a = *raw.surface;
  const LabelledSurface& b = *smoothed.surface;
  ASSERT_EQ(a.mesh.positions.size(), b.mesh.positions.size());
  // Contact vertices with every triangle on one contact (either winding), and how many of them
  // the smoothing left exactly where they were.
  std::vector<int> state(a.mesh.positions.size(), 0);  // 0 none, 1 one contact, 2 other
  std::vector<std::array<uint32_t, 2>> pair(a.mesh.positions.size(), {0, 0});
  size_t mixed = 0;
  for (size_t t = 0; t < a.sides.size(); ++t) {
    const auto [in, out] = a.sides[t];
    const std::array<uint32_t, 2> key{std::min(in, out), std::max(in, out)};
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = a.mesh.indices[3 * t + size_t(k)];
      if (in == 0 || out == 0) {
        state[v] = 2;
      } else if (state[v] == 0) {
        state[v] = 1, pair[v] = key;
      } else if (state[v] == 1 && pair[v] != key) {
        state[v] = 2;
      }
    }
    mixed += in > out && in != 0 && out != 0;
  }
  ASSERT_GT(mixed, 100u) << "the contacts are not wound both ways: the test shows nothing";
  size_t inner = 0, unmoved = 0;
  for (size_t v = 0; v < state.size(); ++v) {
    if (state[v] != 1) continue;
    ++inner;
    const Vec3f p = a.mesh.positions[v], q = b.mesh.positions[v];
    unmoved += p.x == q.x && p.y == q.y && p.z == q.z;
  }
  ASSERT_GT(inner, 1000u);
  EXPECT_LT(double(unmoved), 0.01 * double(inner)) << unmoved << " of " << inner;
  for (const Part& part : smoothed.parts)
    EXPECT_GT(triangle_quality(part.mesh).min, 1e-4) << part.name;
}

// The report's positions before smoothing are the surface's, gathered through the cut after
// smoothing (pipeline.cpp): that needs part_shells' origins to name each shell vertex's surface
// vertex, pinch-split copies included, and the cut of a moved surface to be the same cut.
TEST(JointSmoothing, ShellOriginsNameEachShellVertexsSurfaceVertex) {
  std::mt19937 rng(5);
  size_t split = 0;
  for (int round = 0; round < 12; ++round) {
    const LabelVolume v = test::random_labels(rng, 2 + round % 4);
    for (const bool dual : {false, true}) {
      const test::ExtractedLabels x = test::extract_labels(
          v, 26, [&](const Components& c, const std::vector<size_t>& parts) {
            return dual ? multi_label_dual_contouring(v.grid, c, parts, {.connectivity = 26})
                        : multi_label_marching_cubes(v.grid, c, parts, 26, null_progress());
          });
      const std::string what = "round " + std::to_string(round) + (dual ? " dc" : " mc");
      ShellOrigins origin;
      const std::vector<TriMesh> shells = part_shells(x.surface, &origin);
      // Every surface vertex moved by its own amount, then cut again.
      LabelledSurface moved = x.surface;
      for (size_t i = 0; i < moved.mesh.positions.size(); ++i) {
        Vec3f& q = moved.mesh.positions[i];
        q = {q.x + float(i % 7), q.y + 0.5f, q.z - 1.0f};
      }
      ShellOrigins moved_origin;
      const std::vector<TriMesh> moved_shells = part_shells(moved, &moved_origin);
      ASSERT_EQ(origin.size(), shells.size()) << what;
      EXPECT_EQ(moved_origin, origin) << what;
      for (size_t p = 0; p < shells.size(); ++p) {
        ASSERT_EQ(origin[p].size(), shells[p].positions.size()) << what;
        EXPECT_EQ(shells[p].indices, x.shells[p].indices) << what;
        EXPECT_EQ(moved_shells[p].indices, shells[p].indices) << what;
        for (size_t i = 0; i < origin[p].size(); ++i) {
          const uint32_t from = origin[p][i];
          ASSERT_LT(from, x.surface.mesh.positions.size()) << what;
          const Vec3f a = shells[p].positions[i], b = x.surface.mesh.positions[from];
          const Vec3f c = moved_shells[p].positions[i], d = moved.mesh.positions[from];
          EXPECT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z) << what;
          EXPECT_TRUE(c.x == d.x && c.y == d.y && c.z == d.z) << what;
        }
        std::vector<uint32_t> sorted = origin[p];
        std::sort(sorted.begin(), sorted.end());
        const size_t distinct = size_t(std::unique(sorted.begin(), sorted.end()) - sorted.begin());
        split += sorted.size() - distinct;  // the copies of split vertices
      }
    }
  }
  EXPECT_GT(split, 0u) << "no shell vertex was split: the test misses pinches";
}

TEST(JointSmoothing, RefusesWhatItCannotDo) {
  MeshingOptions o;
  o.surfaces = Surfaces::conforming;
  o.method = Method::dual_contouring;
  EXPECT_NO_THROW(resolve_meshing_options(o));
  o.dc_tolerance_mm = 0.1;
  EXPECT_THROW(resolve_meshing_options(o), Error);
  o.dc_tolerance_mm = 0;
  o.method = Method::marching_cubes;
  o.iso = 100.0;
  EXPECT_THROW(resolve_meshing_options(o), Error);
  o.iso.reset();
  EXPECT_NO_THROW(resolve_meshing_options(o));
  EXPECT_EQ(parse_surfaces("conforming"), Surfaces::conforming);
  EXPECT_EQ(parse_surfaces("independent"), Surfaces::independent);
  EXPECT_FALSE(parse_surfaces("shared").has_value());
}

}  // namespace
}  // namespace segmesh
