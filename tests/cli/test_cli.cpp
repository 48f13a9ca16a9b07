// The segmesh command line end to end: the demo path (phantom -> mesh -> files and report), info,
// and every kind of bad input giving exit code 2, a one-line message and no output file.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli/cli_run.hpp"
#include "segmesh/volume.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh_io/write_volume.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using test::run_segmesh;

std::string q(const fs::path& p) {
  std::string quoted = p.string();  // built in place: GCC 12 warns falsely on "'" + s + "'"
  quoted.insert(quoted.begin(), '\'');
  quoted.push_back('\'');
  return quoted;
}

// A small phantom (the anatomy at 0.394 x 0.394 x 4 mm), written into each test's own folder:
// ctest runs the tests of this file as parallel processes.
fs::path small_phantom(const std::string& test_name) {
  const fs::path p = test::scratch_dir(test_name + "_phantom") / "phantom.nii.gz";
  const auto r = run_segmesh("phantom -o " + q(p) + " --size 256,256,102 --spacing 0.394,0.394,4");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return p;
}

TEST(Cli, MeshWritesEveryFormatAndAReportOfClosedParts) {
  const fs::path dir = test::scratch_dir("cli_mesh");
  const fs::path phantom = small_phantom("cli_mesh");
  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "scene.glb") +
                             " --report " + q(dir / "report.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("label1_1"), std::string::npos) << r.out;
  ASSERT_TRUE(fs::exists(dir / "scene.glb"));

  std::ifstream in(dir / "report.json");
  const auto report = nlohmann::json::parse(in);
  for (const char* key : {"input", "options", "timings_ms", "parts", "totals"}) {
    EXPECT_TRUE(report.contains(key)) << key;
  }
  // Every step of the command is timed, and the steps partition the run: they add up to the
  // total, which is the wall time up to the report (the rest, "other", is small).
  double steps = 0;
  for (const char* key :
       {"read", "components", "extract", "smooth", "write", "measure", "report", "other"}) {
    ASSERT_TRUE(report["timings_ms"].contains(key)) << key;
    EXPECT_GE(report["timings_ms"][key].get<double>(), key == std::string("other") ? -0.01 : 0.0)
        << key;
    steps += report["timings_ms"][key].get<double>();
  }
  const double total = report["timings_ms"]["total"];
  EXPECT_NEAR(steps, total, 1e-6 * total);
  EXPECT_LT(report["timings_ms"]["other"].get<double>(), 0.05 * total);
  EXPECT_EQ(report["input"]["dims"], nlohmann::json({256, 256, 102}));
  EXPECT_EQ(report["parts"].size(), 10u);  // 3 bone parts, plate and 6 screws
  for (const auto& part : report["parts"]) {
    EXPECT_TRUE(part["closed"].get<bool>()) << part["name"];
    EXPECT_EQ(part["boundary_edges"], 0);
    EXPECT_EQ(part["nonmanifold_edges"], 0);
    EXPECT_EQ(part["shells"], 1) << part["name"];
    const double v = part["volume_mm3"], vv = part["voxel_volume_mm3"];
    EXPECT_NEAR(v, vv, 0.1 * vv) << part["name"];
    for (const char* key : {"name", "label", "component", "role", "voxels", "vertices",
                            "triangles", "area_mm2"}) {
      EXPECT_TRUE(part.contains(key)) << key;
    }
  }
  EXPECT_EQ(report["parts"][0]["role"], "bone");
  EXPECT_EQ(report["parts"][3]["role"], "implant");
  EXPECT_TRUE(report["totals"]["all_closed"].get<bool>());

  // The same scene in the other single-file formats reads back with the same triangle count.
  const int64_t triangles = report["totals"]["triangles"];
  for (const char* name : {"scene.ply", "scene.stl", "scene.obj"}) {
    const auto rr = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / name) + " --quiet");
    ASSERT_EQ(rr.exit_code, 0) << rr.err;
    EXPECT_TRUE(rr.out.empty()) << "--quiet printed: " << rr.out;
    const Scene back = read_mesh(dir / name);
    int64_t n = 0;
    for (const Part& p : back.parts) n += static_cast<int64_t>(p.mesh.triangle_count());
    EXPECT_EQ(n, triangles) << name;
  }
  EXPECT_TRUE(fs::exists(dir / "scene.mtl"));
  EXPECT_TRUE(test::folder_holds_only(dir, {"scene.glb", "report.json", "scene.ply", "scene.stl",
                                            "scene.obj", "scene.mtl"}));
}

TEST(Cli, DualContouringWithPresmoothingAndSimplificationGivesClosedParts) {
  const fs::path dir = test::scratch_dir("cli_dc");
  const fs::path phantom = small_phantom("cli_dc");
  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "dc.glb") +
                             " --method dc --presmooth 0.4 --dc-tolerance 0.05 --normals sobel" +
                             " --report " + q(dir / "dc.json") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir / "dc.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["options"]["method"], "dc");
  EXPECT_EQ(report["parts"].size(), 10u);
  EXPECT_TRUE(report["totals"]["all_closed"].get<bool>());
  const auto bad = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "x.glb") + " --method xx");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--method must be mc or dc"), std::string::npos) << bad.err;
}

// --surfaces conforming (the default for label maps with Marching Cubes): the parts of the label
// map as one surface smoothed jointly; the report says which surfaces ran; a bad name, Dual
// Contouring or --iso with conforming surfaces asked for are refused in one line.
TEST(Cli, ConformingSurfacesGiveClosedPartsAndSayWhichRan) {
  const fs::path dir = test::scratch_dir("cli_conforming");
  const fs::path phantom = small_phantom("cli_conforming");
  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "c.glb") +
                             " --surfaces conforming --report " + q(dir / "c.json") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir / "c.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_EQ(report["options"]["surfaces"], "conforming");
  EXPECT_EQ(report["parts"].size(), 10u);
  EXPECT_TRUE(report["totals"]["all_closed"].get<bool>());
  for (const auto& part : report["parts"]) EXPECT_EQ(part["shells"], 1) << part["name"];
  // Six screws and the plate against the bone: each contact listed with its area, no gap.
  ASSERT_TRUE(report["contacts"].is_array());
  EXPECT_GE(report["contacts"].size(), 6u);
  for (const auto& c : report["contacts"]) {
    EXPECT_GT(c["area_mm2"].get<double>(), 1.0) << c;
    EXPECT_LT(c["max_gap_mm"].get<double>(), 1e-4) << c;
  }
  EXPECT_EQ(report["totals"]["contacts"], report["contacts"].size());
  struct Case {
    std::string options, message;
  };
  for (const Case& c : {Case{"--surfaces shared", "--surfaces must be conforming, independent or automatic"},
                        Case{"--surfaces conforming --method dc --dc-tolerance 0.1", "--dc-tolerance simplifies"},
                        Case{"--surfaces conforming --iso 1", "meshes label maps"}}) {
    const auto bad = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "x.glb") + " " + c.options);
    EXPECT_EQ(bad.exit_code, 2) << c.options;
    EXPECT_NE(bad.err.find(c.message), std::string::npos) << c.options << ": " << bad.err;
    EXPECT_FALSE(fs::exists(dir / "x.glb"));
  }
  const auto plain = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "i.glb") +
                                 " --surfaces independent --report " + q(dir / "i.json") +
                                 " --quiet");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  std::ifstream in2(dir / "i.json");
  const auto independent = nlohmann::json::parse(in2);
  EXPECT_EQ(independent["options"]["surfaces"], "independent");
  EXPECT_TRUE(independent["contacts"].is_null());
  EXPECT_TRUE(independent["options"]["surfaces_note"].is_null());

  // The default: conforming on a label map with either method; --presmooth runs independent
  // surfaces and says so once, on stderr and in the report.
  const auto by_default = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "d.glb") +
                                      " --report " + q(dir / "d.json"));
  ASSERT_EQ(by_default.exit_code, 0) << by_default.err;
  EXPECT_EQ(by_default.err.find("note:"), std::string::npos) << by_default.err;
  std::ifstream in3(dir / "d.json");
  EXPECT_EQ(nlohmann::json::parse(in3)["options"]["surfaces"], "conforming");
  const auto dc = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "dc.glb") +
                              " --method dc --report " + q(dir / "dc.json"));
  ASSERT_EQ(dc.exit_code, 0) << dc.err;
  EXPECT_EQ(dc.err.find("note:"), std::string::npos) << dc.err;
  std::ifstream in4(dir / "dc.json");
  const auto dc_report = nlohmann::json::parse(in4);
  EXPECT_EQ(dc_report["options"]["surfaces"], "conforming");
  EXPECT_TRUE(dc_report["options"]["surfaces_note"].is_null());
  ASSERT_TRUE(dc_report["contacts"].is_array());
  EXPECT_GE(dc_report["contacts"].size(), 6u);
  for (const auto& c : dc_report["contacts"]) EXPECT_LT(c["max_gap_mm"].get<double>(), 1e-4) << c;
  const auto presmoothed = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "ps.glb") +
                                       " --presmooth 0.2 --report " + q(dir / "ps.json"));
  ASSERT_EQ(presmoothed.exit_code, 0) << presmoothed.err;
  const size_t note = presmoothed.err.find("note: --presmooth smooths every part's own field");
  EXPECT_NE(note, std::string::npos) << presmoothed.err;
  EXPECT_EQ(presmoothed.err.find("note:", note + 1), std::string::npos) << presmoothed.err;  // once
  std::ifstream in6(dir / "ps.json");
  const auto ps_report = nlohmann::json::parse(in6);
  EXPECT_EQ(ps_report["options"]["surfaces"], "independent");
  EXPECT_NE(ps_report["options"]["surfaces_note"].get<std::string>().find("--presmooth"),
            std::string::npos);
  // The bones alone touch nowhere (the fracture gap, the fibula apart): nothing to say.
  const auto bones = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "b.glb") +
                                 " --labels 1 --method dc --report " + q(dir / "b.json"));
  ASSERT_EQ(bones.exit_code, 0) << bones.err;
  EXPECT_EQ(bones.err.find("note:"), std::string::npos) << bones.err;
  std::ifstream in5(dir / "b.json");
  EXPECT_TRUE(nlohmann::json::parse(in5)["options"]["surfaces_note"].is_null());
}

// --quantize writes a compact GLB (KHR_mesh_quantization) the reader takes back, at most about
// 60 % of the float file, the parts where they were (within the grid's step), and says so in the
// report; for any other format it is refused in one line with nothing written.
TEST(Cli, QuantizeWritesACompactGlbAndIsRefusedForOtherFormats) {
  const fs::path dir = test::scratch_dir("cli_quantize");
  const fs::path phantom = small_phantom("cli_quantize");
  for (const std::string& out : {q(dir / "x.ply"), q(dir / "parts") + "/ --format stl"}) {
    const auto bad = run_segmesh("mesh " + q(phantom) + " -o " + out + " --quantize --quiet");
    EXPECT_EQ(bad.exit_code, 2) << out;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << bad.err;
    EXPECT_NE(bad.err.find("--quantize writes glTF's KHR_mesh_quantization; it needs glb output"),
              std::string::npos)
        << bad.err;
  }
  EXPECT_TRUE(test::folder_holds_only(dir, {}));

  const auto plain = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "f.glb") + " --quiet");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  const auto packed = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "q.glb") +
                                  " --quantize --quiet --report " + q(dir / "q.json"));
  ASSERT_EQ(packed.exit_code, 0) << packed.err;
  EXPECT_LT(double(fs::file_size(dir / "q.glb")), 0.8 * double(fs::file_size(dir / "f.glb")));
  std::ifstream in(dir / "q.json");
  EXPECT_EQ(nlohmann::json::parse(in)["options"]["quantize"], true);
  const Scene a = read_mesh(dir / "f.glb"), b = read_mesh(dir / "q.glb");
  ASSERT_EQ(a.parts.size(), b.parts.size());
  for (size_t p = 0; p < a.parts.size(); ++p) {
    ASSERT_EQ(a.parts[p].mesh.positions.size(), b.parts[p].mesh.positions.size());
    double worst = 0;
    for (size_t v = 0; v < a.parts[p].mesh.positions.size(); ++v) {
      worst = std::max(worst, norm(to_double(a.parts[p].mesh.positions[v]) -
                                   to_double(b.parts[p].mesh.positions[v])));
    }
    EXPECT_LT(worst, 0.01) << a.parts[p].name;  // the small phantom spans well under 500 mm
  }
}

// --atlas with independent surfaces (asked for, or Dual Contouring's), with another extension, on
// -o's file or on a part's file in the -o folder is refused in one line, and nothing is written.
// With conforming surfaces it writes them beside the meshes: one PLY whose faces carry their
// inside and outside materials, with fewer triangles than the parts' shells together (every
// contact meshed once); conforming being the default, --atlas alone does too.
TEST(Cli, AtlasWritesTheConformingSurfaceAndIsRefusedWithoutIt) {
  const fs::path dir = test::scratch_dir("cli_atlas");
  const fs::path phantom = small_phantom("cli_atlas");
  struct Case {
    std::string options, message;
  };
  const std::string in_folder = " --surfaces conforming -o " + q(dir / "parts") + "/ --atlas ";
  for (const Case& c :
       {Case{"-o " + q(dir / "y.glb") + " --surfaces independent --atlas " + q(dir / "b.ply"),
             "--atlas needs --surfaces conforming"},
        Case{"-o " + q(dir / "y.glb") + " --presmooth 0.5 --atlas " + q(dir / "b.ply"),
             "--atlas needs --surfaces conforming, the one surface all parts share; --presmooth "
             "smooths every part's own field"},
        Case{"-o " + q(dir / "y.glb") + " --surfaces conforming --atlas " + q(dir / "b.stl"),
             ".ply or .glb"},
        Case{"-o " + q(dir / "y.glb") + " --surfaces conforming --atlas " + q(dir / "." / "y.glb"),
             "--atlas and -o name the same file"},
        Case{in_folder + q(dir / "parts" / "label1_1.ply"), "names the file of part label1_1"}}) {
    const auto bad = run_segmesh("mesh " + q(phantom) + " " + c.options + " --quiet");
    EXPECT_EQ(bad.exit_code, 2) << c.options;
    EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1) << c.options << ": " << bad.err;
    EXPECT_NE(bad.err.find(c.message), std::string::npos) << c.options << ": " << bad.err;
  }
  EXPECT_TRUE(test::folder_holds_only(dir, {}));
  EXPECT_FALSE(fs::exists(dir / "parts"));

  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "x.glb") +
                             " --surfaces conforming --atlas " + q(dir / "a.ply") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(dir / "a.ply", std::ios::binary);
  std::string header;
  for (std::string line; std::getline(in, line) && line != "end_header";) header += line + "\n";
  EXPECT_NE(header.find("format binary_little_endian 1.0\n"), std::string::npos) << header;
  EXPECT_NE(header.find("property list uchar int vertex_indices\nproperty int inside\n"
                        "property int outside\n"),
            std::string::npos)
      << header;
  EXPECT_NE(header.find("comment material 0 background\n"), std::string::npos) << header;
  EXPECT_NE(header.find("comment material 10 label2_7\n"), std::string::npos) << header;
  const Scene atlas = read_mesh(dir / "a.ply"), parts = read_mesh(dir / "x.glb");
  ASSERT_EQ(atlas.parts.size(), 1u);
  ASSERT_EQ(parts.parts.size(), 10u);
  size_t shell_triangles = 0;
  for (const Part& p : parts.parts) shell_triangles += p.mesh.triangle_count();
  EXPECT_GT(atlas.parts[0].mesh.triangle_count(), shell_triangles / 2);
  EXPECT_LT(atlas.parts[0].mesh.triangle_count(), shell_triangles);
  const auto by_default = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "d.stl") +
                                      " --atlas " + q(dir / "d.glb") + " --quiet");
  EXPECT_EQ(by_default.exit_code, 0) << by_default.err;
  // Dual Contouring's surface is conforming too.
  const auto dc = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "c.glb") +
                              " --method dc --atlas " + q(dir / "c.ply") + " --quiet");
  EXPECT_EQ(dc.exit_code, 0) << dc.err;
  EXPECT_EQ(read_mesh(dir / "c.ply").parts.size(), 1u);
  EXPECT_TRUE(test::folder_holds_only(dir, {"x.glb", "a.ply", "d.stl", "d.glb", "c.glb", "c.ply"}));
}

// Without --iterations each smoothing method runs its own default count (HC 2, Taubin 20, the
// default windowed sinc 20), reported as such; --iterations overrides it.
TEST(Cli, SmoothingIterationsDefaultPerMethod) {
  const fs::path dir = test::scratch_dir("cli_iterations");
  const fs::path phantom = small_phantom("cli_iterations");
  auto iterations = [&](const std::string& options, const std::string& name) {
    const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / (name + ".stl")) + " " + options +
                               " --labels 2 --report " + q(dir / (name + ".json")) + " --quiet");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(dir / (name + ".json"));
    return nlohmann::json::parse(in)["options"]["smooth"]["iterations"].get<int>();
  };
  EXPECT_EQ(iterations("", "default"), 20);
  EXPECT_EQ(iterations("--smooth hc", "hc"), 2);
  EXPECT_EQ(iterations("--smooth hc --iterations 2", "hc2"), 2);
  EXPECT_EQ(iterations("--smooth taubin", "taubin"), 20);
  EXPECT_EQ(iterations("--smooth laplacian --iterations 5", "laplacian5"), 5);
  // And the meshes agree: HC by default is HC with two iterations, not with 20.
  auto bytes = [&](const std::string& name) {
    std::ifstream in(dir / (name + ".stl"), std::ios::binary);
    std::string b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    return b.substr(std::min<size_t>(80, b.size()));  // past the header, which names the file
  };
  EXPECT_TRUE(bytes("hc") == bytes("hc2"));
}

// Decimation through the command line: the budget holds, every part stays closed, and the report
// gives every part's triangles before and after and its distance to the undecimated part.
TEST(Cli, DecimationKeepsTheBudgetAndReportsItsError) {
  const fs::path dir = test::scratch_dir("cli_decimate");
  const fs::path phantom = small_phantom("cli_decimate");
  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "scene.ply") +
                             " --max-triangles 20000 --report " + q(dir / "report.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("decimate "), std::string::npos) << r.out;
  std::ifstream in(dir / "report.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_LE(report["totals"]["triangles"].get<int64_t>(), 20000);
  EXPECT_TRUE(report["totals"]["all_closed"].get<bool>());
  EXPECT_EQ(report["totals"]["max_contact_gap_mm"].get<double>(), 0.0);
  EXPECT_EQ(report["options"]["decimate"]["max_triangles"], 20000);
  EXPECT_GE(report["timings_ms"]["decimate"].get<double>(), 0.0);
  for (const auto& part : report["parts"]) {
    const auto& d = part["decimation"];
    ASSERT_TRUE(d.is_object()) << part["name"];
    EXPECT_GT(d["triangles_before"].get<int64_t>(), d["triangles_after"].get<int64_t>());
    EXPECT_EQ(d["triangles_after"], part["triangles"]);
    EXPECT_GT(d["hausdorff_mm"].get<double>(), 0.0);
    EXPECT_LE(d["p95_mm"].get<double>(), d["hausdorff_mm"].get<double>());
  }
  // Without decimation the field is null.
  const auto plain = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "plain.ply") +
                                 " --report " + q(dir / "plain.json"));
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  std::ifstream plain_in(dir / "plain.json");
  EXPECT_TRUE(nlohmann::json::parse(plain_in)["parts"][0]["decimation"].is_null());
}

TEST(Cli, FolderOutputWritesOneClosedFilePerPart) {
  const fs::path dir = test::scratch_dir("cli_parts");
  const fs::path phantom = small_phantom("cli_parts");
  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "parts") +
                             "/ --format stl --labels 2 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir / "parts")) {
    EXPECT_EQ(entry.path().extension(), ".stl");
    const Scene s = read_mesh(entry.path());
    ASSERT_EQ(s.parts.size(), 1u);
    EXPECT_TRUE(measure_mesh(s.parts[0].mesh).closed()) << entry.path();
    ++files;
  }
  EXPECT_EQ(files, 7);  // the plate and six screws
}

TEST(Cli, InfoReportsLabelsComponentsAndGrid) {
  const fs::path phantom = small_phantom("cli_info");
  const auto r = run_segmesh("info " + q(phantom) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "labels");
  EXPECT_EQ(j["dims"], nlohmann::json({256, 256, 102}));
  EXPECT_NEAR(j["spacing"][2].get<double>(), 4.0, 1e-6);
  ASSERT_EQ(j["labels"].size(), 2u);
  EXPECT_EQ(j["labels"][0]["label"], 1);
  EXPECT_EQ(j["labels"][0]["components"], 3);
  EXPECT_EQ(j["labels"][1]["components"], 7);
  const double voxel = 0.394 * 0.394 * 4;
  EXPECT_NEAR(j["labels"][1]["volume_mm3"].get<double>(),
              j["labels"][1]["voxels"].get<double>() * voxel, 1e-3);
  const auto text = run_segmesh("info " + q(phantom));
  EXPECT_EQ(text.exit_code, 0);
  EXPECT_NE(text.out.find("256 x 256 x 102"), std::string::npos) << text.out;
}

// `info` checks its connectivity as `mesh` does: the same one-line message, exit code 2.
TEST(Cli, InfoRefusesAConnectivityAsMeshDoes) {
  const fs::path phantom = small_phantom("cli_info_connectivity");
  const auto info = run_segmesh("info " + q(phantom) + " --connectivity 7");
  const auto mesh = run_segmesh("mesh " + q(phantom) + " -o " +
                                q(fs::path(phantom).replace_extension(".glb")) +
                                " --connectivity 7");
  EXPECT_EQ(info.exit_code, 2);
  EXPECT_NE(info.err.find("--connectivity must be 6, 18 or 26 (got 7)"), std::string::npos)
      << info.err;
  EXPECT_EQ(info.err, mesh.err);
}

// A small valid label map written as uncompressed NIfTI, for corrupting byte by byte.
fs::path write_labels(const fs::path& dir, const std::string& name, bool foreground = true) {
  LabelVolume v;
  v.grid.dims = {8, 8, 8};
  v.voxels.assign(512, 0);
  if (foreground) v.voxels[v.grid.index(3, 3, 3)] = 1;
  write_volume(v, dir / name);
  return dir / name;
}

void patch(const fs::path& file, size_t offset, const void* bytes, size_t n) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(static_cast<const char*>(bytes), static_cast<std::streamsize>(n));
}

struct BadInput {
  std::string what;
  std::string args;           // after "mesh"
  std::string message;        // a fragment the one-line error must contain
};

TEST(Cli, BadInputsGiveExitCode2AMessageAndNoOutput) {
  const fs::path dir = test::scratch_dir("cli_bad");
  const fs::path good = write_labels(dir, "good.nii");
  const fs::path empty = write_labels(dir, "empty.nii", false);

  const fs::path zero_spacing = write_labels(dir, "zero_spacing.nii");
  const float zero = 0;
  patch(zero_spacing, 80, &zero, 4);  // pixdim[1]
  const fs::path negative_spacing = write_labels(dir, "negative_spacing.nii");
  const float minus = -1;
  patch(negative_spacing, 84, &minus, 4);  // pixdim[2]
  const fs::path two_d = write_labels(dir, "two_d.nii");
  const int16_t two = 2;
  patch(two_d, 40, &two, 2);  // dim[0]
  const fs::path four_d = write_labels(dir, "four_d.nii");
  const int16_t four = 4, frames = 3;
  patch(four_d, 40, &four, 2);
  patch(four_d, 48, &frames, 2);  // dim[4]
  const fs::path truncated = write_labels(dir, "truncated.nii");
  fs::resize_file(truncated, fs::file_size(truncated) - 100);
  const fs::path unknown = dir / "volume.xyz";
  std::ofstream(unknown) << "not a volume";
  const fs::path garbage = dir / "garbage.nii.gz";
  std::ofstream(garbage) << "this is not gzip data at all";

  const std::string out = q(dir / "out.glb");
  const std::vector<BadInput> cases = {
      {"missing file", q(dir / "missing.nii.gz") + " -o " + out, "missing.nii.gz"},
      {"unknown format", q(unknown) + " -o " + out, "volume.xyz"},
      {"corrupt file", q(garbage) + " -o " + out, "garbage.nii.gz"},
      {"truncated file", q(truncated) + " -o " + out, "truncated"},
      {"2-D image", q(two_d) + " -o " + out, "2-D"},
      {"4-D image", q(four_d) + " -o " + out, "4-D"},
      {"zero spacing", q(zero_spacing) + " -o " + out, "spacing"},
      {"negative spacing", q(negative_spacing) + " -o " + out, "spacing"},
      {"label not in volume", q(good) + " -o " + out + " --labels 9", "label 9 is not in the volume"},
      {"no foreground", q(empty) + " -o " + out, "no foreground"},
      {"output folder missing", q(good) + " -o " + q(dir / "nowhere" / "out.glb"), "does not exist"},
      {"unknown output format", q(good) + " -o " + q(dir / "out.xyz"), "unknown mesh format"},
      {"bad connectivity", q(good) + " -o " + out + " --connectivity 7", "connectivity"},
      {"bad normals", q(good) + " -o " + out + " --normals magic", "--normals"},
      {"smoothing factor out of range", q(good) + " -o " + out + " --smooth hc --alpha 2",
       "--alpha must be between 0 and 1 (got 2)"},
      {"negative iterations", q(good) + " -o " + out + " --iterations -3", "--iterations"},
      {"pass band zero", q(good) + " -o " + out + " --pass-band 0", "--pass-band"},
      {"not a number", q(good) + " -o " + out + " --presmooth wide", "--presmooth expects a number"},
      {"label list", q(good) + " -o " + out + " --labels 1,x", "--labels expects whole numbers"},
      {"negative decimation error", q(good) + " -o " + out + " --decimate-error -0.5",
       "--decimate-error must be a non-negative number of millimetres (got -0.5)"},
      {"negative budget", q(good) + " -o " + out + " --max-triangles -5",
       "--max-triangles must not be negative"},
      {"budget not a number", q(good) + " -o " + out + " --max-triangles-per-part lots",
       "--max-triangles-per-part expects a whole number"},
      {"output is the input", q(good) + " -o " + q(good), ""},
  };
  for (const BadInput& c : cases) {
    const auto r = run_segmesh("mesh " + c.args);
    EXPECT_EQ(r.exit_code, 2) << c.what << ": " << r.err;
    EXPECT_EQ(r.err.rfind("segmesh: error: ", 0), 0u) << c.what << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.what << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.what << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.glb")) << c.what;
  }
  EXPECT_FALSE(fs::exists(dir / "nowhere"));
  // Nothing but the inputs is left in the folder: no partial outputs, no temporary files.
  EXPECT_TRUE(test::folder_holds_only(
      dir, {"good.nii", "empty.nii", "zero_spacing.nii", "negative_spacing.nii", "two_d.nii",
            "four_d.nii", "truncated.nii", "volume.xyz", "garbage.nii.gz"}));
}

TEST(Cli, FloatVolumeNeedsIso) {
  SEGMESH_DATA_FILE(map, "mrc/EMD-3197.map");
  const fs::path dir = test::scratch_dir("cli_float");
  auto r = run_segmesh("mesh " + q(map) + " -o " + q(dir / "map.ply"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--iso"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "map.ply"));
  r = run_segmesh("info " + q(map) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "grey");
  const double mid = 0.5 * (j["value_range"]["min"].get<double>() + j["value_range"]["max"].get<double>());
  r = run_segmesh("mesh " + q(map) + " -o " + q(dir / "map.ply") + " --iso " + std::to_string(mid) +
                  " --quiet");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "map.ply"));
}

TEST(Cli, UsageErrorsAndHelp) {
  auto r = run_segmesh("");
  EXPECT_EQ(r.exit_code, 2);
  r = run_segmesh("mesh");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("segmesh: error:"), std::string::npos);
  r = run_segmesh("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* cmd : {"info", "mesh", "phantom"}) EXPECT_NE(r.out.find(cmd), std::string::npos);
  r = run_segmesh("phantom -o /nonexistent-folder/p.nii.gz");
  EXPECT_EQ(r.exit_code, 2);
  r = run_segmesh("phantom -o x.nii.gz --size 5,5");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--size"), std::string::npos);
}

}  // namespace
}  // namespace segmesh

namespace segmesh {
namespace {

TEST(Cli, StudyWritesTheThreeTablesJsonAndColourCodedMeshes) {
  const fs::path dir = test::scratch_dir("cli_study");
  // A small phantom keeps the study (many smoothings, each with a deviation) quick.
  const fs::path phantom = dir / "phantom.nii.gz";
  ASSERT_EQ(run_segmesh("phantom -o " + q(phantom) + " --size 128,128,51 --spacing 0.8,0.8,8 --quiet").exit_code, 0);
  const auto r = run_segmesh("study " + q(phantom) + " -o " + q(dir / "study") + " --labels 1 --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream md_in(dir / "study" / "study.md");
  const std::string md((std::istreambuf_iterator<char>(md_in)), std::istreambuf_iterator<char>());
  for (const char* heading : {"## Table 1", "## Table 2", "## Table 3", "Reference thesis", "hc", "taubin", "sinc"}) {
    EXPECT_NE(md.find(heading), std::string::npos) << heading;
  }
  std::ifstream json_in(dir / "study" / "study.json");
  const auto j = nlohmann::json::parse(json_in);
  ASSERT_EQ(j["extractions"].size(), 2u);
  const auto& mc = j["extractions"][0];
  EXPECT_EQ(mc["method"], "mc");
  ASSERT_GE(mc["smoothing"].size(), 10u);
  // Laplacian shrinks more than HC, both reported with a deviation from the unsmoothed surface.
  double laplacian = 0, hc = 0;
  for (const auto& s : mc["smoothing"]) {
    if (s["iterations"] != 2) continue;
    if (s["method"] == "laplacian") laplacian = s["volume_change_percent"];
    if (s["method"] == "hc") hc = s["volume_change_percent"];
    EXPECT_GT(s["deviation_mm"]["hausdorff"].get<double>(), 0.0);
  }
  EXPECT_LT(laplacian, hc);
  EXPECT_LT(std::abs(hc), 0.6);
  // Pictures of the meshes (rendered headless), linked from study.md.
  ASSERT_EQ(j["pictures"].size(), 6u);
  for (const char* png : {"mc.png", "dc.png", "mc_sinc.png", "mc_quality.png", "dc_quality.png",
                          "mc_sinc_quality.png"}) {
    const auto [w, h] = test::png_size(dir / "study" / png);
    EXPECT_TRUE(w >= 360 && h >= 360 && std::max(w, h) == 720) << png << " " << w << "x" << h;
    EXPECT_NE(md.find(std::string("](") + png + ")"), std::string::npos) << png;
  }
  for (const char* mesh : {"mc_quality.glb", "dc_quality.glb"}) {
    ASSERT_TRUE(fs::exists(dir / "study" / mesh)) << mesh;
    const Scene s = read_mesh(dir / "study" / mesh);
    ASSERT_FALSE(s.parts.empty());
    EXPECT_EQ(s.parts[0].mesh.colors.size(), s.parts[0].mesh.positions.size()) << "quality colours";
  }
}

}  // namespace
}  // namespace segmesh

namespace segmesh {
namespace {

TEST(Cli, ColorQualityWritesRadiiRatioColoursIntoPlyAndGlb) {
  const fs::path dir = test::scratch_dir("cli_color");
  const fs::path phantom = small_phantom("cli_color");
  for (const char* name : {"q.ply", "q.glb"}) {
    const auto r = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / name) + " --color quality --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Scene s = read_mesh(dir / name);
    bool blueish = false, greenish = false;
    for (const Part& p : s.parts) {
      ASSERT_EQ(p.mesh.colors.size(), p.mesh.positions.size()) << name;
      for (const Rgba8& c : p.mesh.colors) {
        EXPECT_EQ(c[0], 0);
        blueish = blueish || c[2] > 200;
        greenish = greenish || c[1] > 200;
      }
    }
    EXPECT_TRUE(blueish && greenish) << name << ": poor and good triangles both coloured";
  }
  const auto bad = run_segmesh("mesh " + q(phantom) + " -o " + q(dir / "x.ply") + " --color pink");
  EXPECT_EQ(bad.exit_code, 2);
}

}  // namespace
}  // namespace segmesh
