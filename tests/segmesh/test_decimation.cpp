// Decimation (decimation.hpp) through build_scene: every part closed, manifold and outward
// afterwards, budgets respected, the error bound checked by an independent measurement (exact
// point-to-mesh distances from the vertices and from points spread over every triangle of both
// meshes, not the decimator's quadric estimate), contacts still shared, no part crossing another,
// and bad option values refused.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "segmesh/decimation.hpp"
#include "segmesh/error.hpp"
#include "segmesh/mesh_distance.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/meshing_options.hpp"
#include "segmesh/phantom.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh/quality.hpp"
#include "segmesh/scene_measures.hpp"
#include "support/mesh_crossings.hpp"
#include "support/sound_parts.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

// A ball of radius 12 voxels (0.5 mm voxels) with a smaller ball (label 2) set into its side.
LabelVolume ball(bool with_inlay) {
  LabelVolume v = test::blank_labels({40, 40, 40}, {0.5, 0.5, 0.5});
  for (int64_t k = 0; k < 40; ++k)
    for (int64_t j = 0; j < 40; ++j)
      for (int64_t i = 0; i < 40; ++i) {
        const double x = double(i) - 19.5, y = double(j) - 19.5, z = double(k) - 19.5;
        int32_t label = 0;
        if (x * x + y * y + z * z < 144) label = 1;
        if (with_inlay && (x - 10) * (x - 10) + y * y + z * z < 25) label = 2;
        v.at(i, j, k) = label;
      }
  return v;
}

Image small_phantom() {
  return test::label_image(make_phantom({.size = {256, 256, 102}, .spacing = {0.394, 0.394, 4}}));
}

// Points of every triangle: its corners, centroid, edge midpoints and three inner points.
std::vector<Vec3d> surface_samples(const TriMesh& m) {
  std::vector<Vec3d> out;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const Vec3d a = to_double(m.positions[m.indices[3 * t]]);
    const Vec3d b = to_double(m.positions[m.indices[3 * t + 1]]);
    const Vec3d c = to_double(m.positions[m.indices[3 * t + 2]]);
    for (const auto& w : {std::array{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0},
                          {1 / 3.0, 1 / 3.0, 1 / 3.0}, {0.5, 0.5, 0.0}, {0.0, 0.5, 0.5},
                          {0.5, 0.0, 0.5}, {2 / 3.0, 1 / 6.0, 1 / 6.0}, {1 / 6.0, 2 / 3.0, 1 / 6.0},
                          {1 / 6.0, 1 / 6.0, 2 / 3.0}})
      out.push_back(w[0] * a + w[1] * b + w[2] * c);
  }
  return out;
}

// The largest distance of either mesh's samples to the other mesh.
double sampled_hausdorff(const TriMesh& a, const TriMesh& b) {
  const MeshDistance to_a(a), to_b(b);
  double worst = 0;
  for (const Vec3d& p : surface_samples(a)) worst = std::max(worst, to_b.distance(p));
  for (const Vec3d& p : surface_samples(b)) worst = std::max(worst, to_a.distance(p));
  return worst;
}

int64_t slivers(const TriMesh& m) {
  int64_t n = 0;
  for (size_t t = 0; t < m.triangle_count(); ++t) {
    const uint32_t* i = &m.indices[3 * t];
    n += radii_ratio(to_double(m.positions[i[0]]), to_double(m.positions[i[1]]),
                     to_double(m.positions[i[2]])) < 0.05;
  }
  return n;
}

// Sound shells (support/sound_parts.hpp), none below the minimum.
void expect_sound_parts(const Scene& scene) {
  test::expect_sound_shells(scene);
  for (const Part& part : scene.parts)
    EXPECT_GE(int64_t(part.mesh.triangle_count()), kMinPartTriangles) << part.name;
}

int64_t total_triangles(const Scene& scene) {
  int64_t n = 0;
  for (const Part& part : scene.parts) n += int64_t(part.mesh.triangle_count());
  return n;
}

// Every vertex of every contact of a decimated conforming scene lies on both parts' shells, and
// no part crosses another.
void expect_contacts_shared(const Scene& after) {
  ASSERT_TRUE(after.surface.has_value());
  const LabelledSurface& s = *after.surface;
  std::vector<MeshDistance> shells;
  for (const Part& part : after.parts) shells.emplace_back(part.mesh);
  size_t contact_vertices = 0;
  double worst = 0;
  for (size_t t = 0; t < s.sides.size(); ++t) {
    const auto [in, out] = s.sides[t];
    if (in == 0 || out == 0) continue;
    for (int k = 0; k < 3; ++k) {
      const Vec3d p = to_double(s.mesh.positions[s.mesh.indices[3 * t + size_t(k)]]);
      worst = std::max({worst, shells[in - 1].distance(p), shells[out - 1].distance(p)});
      ++contact_vertices;
    }
  }
  EXPECT_GT(contact_vertices, 100u);
  EXPECT_LT(worst, 1e-4);
  const SceneMeasures m = measure_scene(after, {});
  ASSERT_EQ(m.contacts.size(), 8u);
  for (const ContactMeasures& c : m.contacts) {
    EXPECT_EQ(test::crossings(after.parts[c.a].mesh, after.parts[c.b].mesh), 0u)
        << after.parts[c.a].name << " " << after.parts[c.b].name;
  }
}

// Float tolerance on the error bound: positions are stored in float (1e-6 relative of ~100 mm).
constexpr double kFloatTolerance = 1e-4;

TEST(Decimation, ABallKeepsItsShapeWithinTheErrorBound) {
  const Image image = test::label_image(ball(false));
  MeshingOptions o;
  const Scene before = build_scene(image, o);
  o.decimate.error_mm = 0.2;
  const Scene after = build_scene(image, o);
  ASSERT_EQ(after.parts.size(), 1u);
  expect_sound_parts(after);
  const size_t n0 = before.parts[0].mesh.triangle_count(), n1 = after.parts[0].mesh.triangle_count();
  EXPECT_LT(n1 * 3, n0) << n0 << " -> " << n1;
  EXPECT_LE(sampled_hausdorff(before.parts[0].mesh, after.parts[0].mesh), 0.2 + kFloatTolerance);
  // The volume stays within 1 %.
  EXPECT_NEAR(enclosed_volume(after.parts[0].mesh), enclosed_volume(before.parts[0].mesh),
              0.01 * enclosed_volume(before.parts[0].mesh));
}

TEST(Decimation, BudgetsAreRespectedOnBothKindsOfSurfaces) {
  const Image image = test::label_image(ball(true));
  for (Surfaces surfaces : {Surfaces::conforming, Surfaces::independent}) {
    MeshingOptions o;
    o.surfaces = surfaces;
    o.decimate.max_triangles = 600;
    const Scene scene = build_scene(image, o);
    ASSERT_EQ(scene.parts.size(), 2u);
    expect_sound_parts(scene);
    EXPECT_LE(total_triangles(scene), 600) << surfaces_name(surfaces);
    o.decimate = {.max_triangles_per_part = 200};
    const Scene per_part = build_scene(image, o);
    expect_sound_parts(per_part);
    for (const Part& part : per_part.parts) EXPECT_LE(part.mesh.triangle_count(), 200u) << part.name;
  }
  // A budget below the minimum leaves every part at the minimum or a little above on independent
  // surfaces; on conforming ones the junction curve between ball, inlay and background, whose
  // vertices collapse only along it and whose ends never move, keeps more.
  for (Surfaces surfaces : {Surfaces::conforming, Surfaces::independent}) {
    MeshingOptions o;
    o.surfaces = surfaces;
    o.decimate.max_triangles_per_part = 4;
    const Scene tiny = build_scene(image, o);
    expect_sound_parts(tiny);
    for (const Part& part : tiny.parts)
      EXPECT_LE(part.mesh.triangle_count(), surfaces == Surfaces::independent ? 64u : 160u)
          << part.name;
  }
}

// A scene budget on the conforming phantom: one order of collapses over all parts, so the scene
// ends at its budget (not below it, as shares by area rounded down and contacts counted twice
// left it) and the error stays within two voxels of the smallest spacing everywhere.
TEST(Decimation, ThePhantomToABudgetStaysWithinTwoVoxels) {
  const Image image = small_phantom();
  MeshingOptions o;
  const Scene before = build_scene(image, o);
  o.decimate.max_triangles = 12000;  // about 1/19 of the test-size phantom
  const Scene after = build_scene(image, o);
  ASSERT_TRUE(after.surface.has_value());
  expect_sound_parts(after);
  const int64_t n = total_triangles(after);
  EXPECT_LE(n, 12000);
  EXPECT_GE(n, 11800);
  const double two_voxels = 2 * 0.394;
  for (size_t p = 0; p < after.parts.size(); ++p) {
    EXPECT_LE(sampled_hausdorff(before.parts[p].mesh, after.parts[p].mesh), two_voxels)
        << after.parts[p].name;
  }
  expect_contacts_shared(after);  // the block phase ran (a budget alone)
}

// The witnesses hold every original vertex within the bound through the collapses, the flips
// and the relaxation, on independent surfaces too: the full-size phantom's plate (voxels of
// 0.197 x 0.197 x 2 mm, a thin part with sharp rims) had four vertices 0.228 mm away while the
// relaxation's moves went unchecked.
TEST(Decimation, OriginalVerticesStayWithinTheBoundOnIndependentSurfaces) {
  // The grid as a NIfTI file of `segmesh phantom` holds it (single-precision spacing and origin).
  LabelVolume v = make_phantom({.spacing = {double(0.197f), double(0.197f), 2.0}});
  for (double& x : v.grid.origin) x = double(float(x));
  const Image image = test::label_image(std::move(v));
  MeshingOptions o;
  o.labels = {2};
  o.surfaces = Surfaces::independent;
  const Scene before = build_scene(image, o);
  o.decimate.error_mm = 0.2;
  const Scene after = build_scene(image, o);
  ASSERT_EQ(after.parts.size(), before.parts.size());
  expect_sound_parts(after);
  for (size_t p = 0; p < after.parts.size(); ++p) {
    const MeshDistance to_after(after.parts[p].mesh);
    double worst = 0;
    for (const Vec3f& v : before.parts[p].mesh.positions)
      worst = std::max(worst, to_after.distance(to_double(v)));
    EXPECT_LE(worst, 0.2) << after.parts[p].name;
    // The witnesses bound the original vertices only: the triangles' insides, both ways, need
    // the rest of the bound (the plate's 0.191 mm, measured with 45 points a triangle).
    EXPECT_LE(sampled_hausdorff(before.parts[p].mesh, after.parts[p].mesh), 0.2 + kFloatTolerance)
        << after.parts[p].name;
    EXPECT_LT(after.parts[p].mesh.triangle_count(), before.parts[p].mesh.triangle_count() / 4)
        << after.parts[p].name;
  }
}

TEST(Decimation, ThePhantomWithinTwoTenthsOfAMillimetreKeepsItsContacts) {
  const Image image = small_phantom();
  MeshingOptions o;
  const Scene before = build_scene(image, o);
  o.decimate.error_mm = 0.2;
  const Scene after = build_scene(image, o);
  ASSERT_TRUE(after.surface.has_value());
  ASSERT_EQ(after.parts.size(), before.parts.size());
  expect_sound_parts(after);
  int64_t slivers_before = 0, slivers_after = 0;
  for (size_t p = 0; p < after.parts.size(); ++p) {
    const TriMesh& a = before.parts[p].mesh;
    const TriMesh& b = after.parts[p].mesh;
    EXPECT_LE(sampled_hausdorff(a, b), 0.2 + kFloatTolerance) << after.parts[p].name;
    slivers_before += slivers(a);
    slivers_after += slivers(b);
  }
  const int64_t n0 = total_triangles(before), n1 = total_triangles(after);
  EXPECT_GE(n0, 5 * n1) << n0 << " -> " << n1;
  // Decimation makes no new sliver, and the flips that may use the whole bound (checked
  // against the original surface both ways) leave at most 0.2 % of the triangles slivers: 34 of
  // 30 838 when they were allowed, 379 of 30 798 when they took only what the corners' quadrics
  // left of the bound.
  EXPECT_LE(slivers_after, slivers_before);
  EXPECT_LE(500 * slivers_after, n1) << slivers_after << " slivers in " << n1 << " triangles";
  std::printf("phantom (test size): %lld -> %lld triangles, slivers %lld -> %lld\n",
              (long long)n0, (long long)n1, (long long)slivers_before, (long long)slivers_after);

  expect_contacts_shared(after);
}

TEST(Decimation, TheReportMeasuresTheDecimatedPartsAgainstTheUndecimatedOnes) {
  const Image image = test::label_image(ball(true));
  MeshingOptions o;
  o.decimate.error_mm = 0.1;
  ExtractedPositions extracted;
  const Scene scene = build_scene(image, o, null_progress(), nullptr, &extracted);
  ASSERT_EQ(extracted.undecimated.size(), scene.parts.size());
  const SceneMeasures m = measure_scene(scene, {.extracted = &extracted});
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const PartMeasures& pm = m.parts[p];
    ASSERT_TRUE(pm.decimation_deviation.has_value());
    EXPECT_EQ(*pm.triangles_before_decimation, int64_t(extracted.undecimated[p].triangle_count()));
    EXPECT_GT(*pm.triangles_before_decimation, int64_t(scene.parts[p].mesh.triangle_count()));
    EXPECT_GT(pm.decimation_deviation->hausdorff, 0);
    EXPECT_LE(pm.decimation_deviation->p95, pm.decimation_deviation->hausdorff);
    EXPECT_LE(pm.decimation_deviation->hausdorff,
              sampled_hausdorff(extracted.undecimated[p], scene.parts[p].mesh) + 1e-9);
    ASSERT_TRUE(pm.smoothing_deviation.has_value());
  }
}

void expect_same_meshes(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (size_t p = 0; p < a.parts.size(); ++p) {
    EXPECT_EQ(a.parts[p].mesh.indices, b.parts[p].mesh.indices);
    ASSERT_EQ(a.parts[p].mesh.positions.size(), b.parts[p].mesh.positions.size());
    EXPECT_TRUE(std::equal(a.parts[p].mesh.positions.begin(), a.parts[p].mesh.positions.end(),
                           b.parts[p].mesh.positions.begin(), [](Vec3f x, Vec3f y) {
                             return x.x == y.x && x.y == y.y && x.z == y.z;
                           }));
  }
}

TEST(Decimation, IsDeterministic) {
  const Image image = small_phantom();
  MeshingOptions o;
  o.decimate.max_triangles = 20000;
  const Scene a = build_scene(image, o), b = build_scene(image, o);
  EXPECT_LE(total_triangles(a), 20000);
  expect_same_meshes(a, b);
}

// The block phase (on by default; the test-size phantom's surface has about
// 116 000 vertices, 7 blocks) keeps the parts sound and, here, the bound, and its result does
// not depend on the thread count; without it the loop alone does the same.
TEST(Decimation, BlocksKeepTheBoundAndDoNotDependOnTheThreadCount) {
  const Image image = small_phantom();
  MeshingOptions o;
  const Scene before = build_scene(image, o);
  using Blocks = DecimateOptions::Blocks;
  for (const Blocks blocks : {Blocks::kOn, Blocks::kOff}) {
    o.decimate.error_mm = 0.2;
    o.decimate.blocks = blocks;
    const bool with = blocks == Blocks::kOn;
    const Scene several = build_scene(image, o);
    expect_sound_parts(several);
    ASSERT_EQ(several.parts.size(), before.parts.size());
    for (size_t p = 0; p < several.parts.size(); ++p)
      EXPECT_LE(sampled_hausdorff(before.parts[p].mesh, several.parts[p].mesh),
                0.2 + kFloatTolerance)
          << several.parts[p].name << (with ? " (blocks)" : " (loop)");
    EXPECT_GE(total_triangles(before), 5 * total_triangles(several));
    expect_contacts_shared(several);
    o.decimate.error_mm = 0;
    o.decimate.max_triangles = 20000;
    const Scene budget = build_scene(image, o);
    expect_sound_parts(budget);
    EXPECT_LE(total_triangles(budget), 20000);
    EXPECT_GE(total_triangles(budget), 19000);
    expect_contacts_shared(budget);
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    expect_same_meshes(budget, build_scene(image, o));
    o.decimate.max_triangles = 0;
    o.decimate.error_mm = 0.2;
    expect_same_meshes(several, build_scene(image, o));
  }
}

TEST(Decimation, BadValuesAreRefusedNamingTheOption) {
  auto message = [](auto&& set) {
    MeshingOptions o;
    set(o);
    try {
      resolve_meshing_options(o);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message([](MeshingOptions& o) { o.decimate.error_mm = -0.5; }),
            "--decimate-error must be a non-negative number of millimetres (got -0.5)");
  EXPECT_NE(message([](MeshingOptions& o) { o.decimate.error_mm = NAN; }).find("--decimate-error"),
            std::string::npos);
  EXPECT_EQ(message([](MeshingOptions& o) { o.decimate.max_triangles = -1; }),
            "--max-triangles must not be negative (0: no budget) (got -1)");
  EXPECT_EQ(message([](MeshingOptions& o) { o.decimate.max_triangles_per_part = -7; }),
            "--max-triangles-per-part must not be negative (0: no budget) (got -7)");
  MeshingOptions o;
  EXPECT_THROW(find_meshing_option("max-triangles")->set(o, "many"), Error);
  find_meshing_option("--decimate-error")->set(o, "0.25");
  EXPECT_EQ(o.decimate.error_mm, 0.25);
}

TEST(Decimation, BudgetsFollowTheAreas) {
  const std::vector<int64_t> b =
      part_triangle_budgets({300, 100}, {.max_triangles = 1000, .max_triangles_per_part = 500});
  EXPECT_EQ(b, (std::vector<int64_t>{500, 250}));
  EXPECT_EQ(part_triangle_budgets({1, 1}, {.error_mm = 0.1}), (std::vector<int64_t>{0, 0}));
  // Small parts keep the minimum; the larger ones give up what that costs, so the shares still
  // add up to the budget at most.
  const std::vector<int64_t> small =
      part_triangle_budgets({1000, 10, 10, 10}, {.max_triangles = 1000});
  EXPECT_EQ(small[1], kMinPartTriangles);
  EXPECT_EQ(small[3], kMinPartTriangles);
  EXPECT_LE(small[0] + small[1] + small[2] + small[3], 1000);
  EXPECT_GE(small[0] + small[1] + small[2] + small[3], 995);
  // Below what the minimum allows, every part gets the minimum.
  EXPECT_EQ(part_triangle_budgets({1, 1}, {.max_triangles = 40}),
            (std::vector<int64_t>{kMinPartTriangles, kMinPartTriangles}));
}

}  // namespace
}  // namespace segmesh
