// The mesh report on a many-part scene (a random label map, as automatic segmenters and the
// stress case of issue 40 give): every part's entry, every contact, the totals and the timings,
// read back with a JSON parser and checked against the measures they come from.
#include "segmesh_io/mesh_report.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/test_fields.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;

TEST(MeshReport, ManyPartsEveryEntryAndContactAsMeasured) {
  const fs::path dir = test::scratch_dir("mesh_report_many");
  const Image image = test::label_image(test::random_labels({14, 14, 14}, 255, 1.0, 40));
  const MeshingOptions options = resolve_meshing_options(MeshingOptions{});
  ExtractedPositions extracted;
  PipelineStats stats;
  Scene scene = build_scene(image, options, null_progress(), &stats, &extracted);
  ASSERT_GT(scene.parts.size(), 2000u);
  ASSERT_TRUE(scene.conforming);
  // Names that need escaping in JSON, and one that is not UTF-8.
  scene.parts[0].name = "quote\" back\\slash\nline";
  scene.parts[1].name = "f\xe9mur";
  const SceneMeasures measures = measure_scene(scene, {.extracted = &extracted});
  ReportedRequest request{.options = options, .target = {.path = dir / "scene.glb", .format = MeshFormat::glb}};
  MeshTimings t{.read = 1, .components = 2, .extract = 3, .smooth = 4, .write = 5, .measure = 6};
  const auto start = std::chrono::steady_clock::now() - std::chrono::milliseconds(30);
  write_mesh_report(dir / "report.json", image, request, t, start, stats, scene, measures, {"scene.glb"});

  std::ifstream in(dir / "report.json");
  const nlohmann::json r = nlohmann::json::parse(in);
  ASSERT_EQ(r["parts"].size(), scene.parts.size());
  EXPECT_EQ(r["parts"][0]["name"], scene.parts[0].name);
  EXPECT_EQ(r["parts"][1]["name"], "f\xef\xbf\xbdmur");
  int64_t triangles = 0;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const nlohmann::json& e = r["parts"][p];
    const Part& part = scene.parts[p];
    const MeshMeasures& m = measures.parts[p].mesh;
    if (p > 1) {
      ASSERT_EQ(e["name"], part.name) << p;
    }
    EXPECT_EQ(e["label"], part.label);
    EXPECT_EQ(e["component"], part.component);
    EXPECT_EQ(e["role"], std::string(role_name(part.role)));
    EXPECT_EQ(e["voxels"], part.voxels);
    EXPECT_EQ(e["vertices"], m.vertices);
    EXPECT_EQ(e["triangles"], m.triangles);
    EXPECT_EQ(e["area_mm2"].get<double>(), m.area_mm2);  // exactly: shortest round-trip text
    EXPECT_EQ(e["volume_mm3"].get<double>(), m.volume_mm3);
    EXPECT_EQ(e["closed"], m.closed());
    EXPECT_EQ(e["shells"], m.shells);
    EXPECT_EQ(e["radii_ratio"]["min"].get<double>(), measures.parts[p].quality->min);
    EXPECT_EQ(e["smoothing_deviation_mm"]["hausdorff"].get<double>(),
              measures.parts[p].smoothing_deviation->hausdorff);
    EXPECT_TRUE(e["decimation"].is_null());
    EXPECT_EQ(e.size(), 21u);  // the 21 members, none twice
    triangles += m.triangles;
  }
  ASSERT_EQ(r["contacts"].size(), measures.contacts.size());
  ASSERT_GT(measures.contacts.size(), 1000u);
  for (size_t i = 0; i < measures.contacts.size(); ++i) {
    const ContactMeasures& c = measures.contacts[i];
    EXPECT_EQ(r["contacts"][i]["parts"][1], scene.parts[c.b].name);
    EXPECT_EQ(r["contacts"][i]["area_mm2"].get<double>(), c.area_mm2);
    EXPECT_EQ(c.max_gap_mm, 0.0);  // the shells are cut from the surface
  }
  EXPECT_EQ(r["totals"]["parts"], scene.parts.size());
  EXPECT_EQ(r["totals"]["triangles"], triangles);
  EXPECT_EQ(r["totals"]["contacts"], measures.contacts.size());
  EXPECT_EQ(r["totals"]["max_contact_gap_mm"].get<double>(), 0.0);
  EXPECT_EQ(r["outputs"], nlohmann::json::array({"scene.glb"}));
  EXPECT_EQ(r["input"]["dims"], nlohmann::json({14, 14, 14}));
  EXPECT_EQ(r["options"]["surfaces"], "conforming");
  EXPECT_EQ(r["timings_ms"]["smooth"].get<double>(), 4.0);
  EXPECT_EQ(r["timings_ms"]["report"].get<double>(), t.report);
  EXPECT_GE(r["timings_ms"]["total"].get<double>(), 30.0);
  EXPECT_NEAR(r["timings_ms"]["other"].get<double>(), t.total - t.steps(), 1e-9);
}

}  // namespace
}  // namespace segmesh
