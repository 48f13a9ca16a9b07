// `segmesh quality` end to end: on the phantom's meshes in every format, and on hand-made files
// with every kind of defect, its numbers agree with the peer scoring script
// ../shared/tools/mesh_metrics.py (the tests skip, saying so, when the script is absent); bad files
// give exit code 2 and a one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/cli_run.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using test::run_segmesh;

std::string q(const fs::path& p) {
  std::string quoted = p.string();  // built in place: GCC 12 warns falsely on "'" + s + "'"
  quoted.insert(quoted.begin(), '\'');
  quoted.push_back('\'');
  return quoted;
}

fs::path mesh_metrics_script() {
  return fs::path(SEGMESH_SOURCE_DIR).parent_path() / "shared" / "tools" / "mesh_metrics.py";
}

bool python_numpy_available() {
  return std::system("/usr/bin/python3 -c 'import numpy' >/dev/null 2>&1") == 0;
}

// Declares `script`, the peer scoring script; skips the test when it is absent, fails when it is
// present but cannot run for want of numpy.
#define REQUIRE_MESH_METRICS(script)                                      \
  const fs::path script = mesh_metrics_script();                          \
  if (!fs::exists(script))                                                \
    GTEST_SKIP() << script.string()                                       \
                 << " not found (the peer scoring script beside the "     \
                    "checkout); the agreement with it is not checked";    \
  if (!python_numpy_available())                                          \
  FAIL() << script.string()                                               \
         << " needs /usr/bin/python3 with numpy (Debian python3-numpy); " \
            "run scripts/install-deps.sh"

// mesh_metrics.py's JSON object for each file, in order.
std::vector<json> mesh_metrics(const fs::path& script, const std::vector<fs::path>& files) {
  std::string command = "/usr/bin/python3 " + q(script);
  for (const fs::path& f : files) {
    command += ' ';
    command += q(f);
  }
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) {
    ADD_FAILURE() << "cannot run " << command;
    return {};
  }
  std::string out;
  char buffer[4096];
  while (size_t n = fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = pclose(pipe);
  EXPECT_EQ(status, 0) << command;
  std::vector<json> results;
  std::istringstream lines(out);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty()) results.push_back(json::parse(line));
  }
  EXPECT_EQ(results.size(), files.size()) << command << "\n" << out;
  return results;
}

json quality(const fs::path& file) {
  const auto r = run_segmesh("quality " + q(file) + " --json");
  EXPECT_EQ(r.exit_code, 0) << file << ": " << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  return r.exit_code == 0 ? json::parse(r.out) : json::object();
}

bool scipy_note_printed = false;

// Our numbers for one mesh (a part, or "all") against mesh_metrics.py's for the same mesh.
void expect_agreement(const json& ours, const json& theirs, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_TRUE(ours.is_object() && theirs.is_object());
  EXPECT_EQ(ours["vertices"], theirs["n_vertices"]);
  EXPECT_EQ(ours["triangles"], theirs["n_triangles"]);
  const auto relative = [](const json& a, const json& b, const char* name) {
    const double x = a.get<double>(), y = b.get<double>();
    EXPECT_NEAR(x, y, 1e-6 * std::max(1.0, std::abs(y))) << name;
  };
  relative(ours["area_mm2"], theirs["area"], "area");
  relative(ours["volume_mm3"], theirs["volume"], "volume");
  if (theirs["n_triangles"] == 0) return;
  EXPECT_EQ(ours["edges"], theirs["n_edges"]);
  relative(ours["mean_edge_length_mm"], theirs["edge_len_mean"], "mean edge length");
  const json& rho = ours["radii_ratio"];
  EXPECT_NEAR(rho["min"].get<double>(), theirs["rho_min"].get<double>(), 1e-6) << "rho min";
  EXPECT_NEAR(rho["mean"].get<double>(), theirs["rho_mean"].get<double>(), 1e-6) << "rho mean";
  EXPECT_NEAR(rho["p01"].get<double>(), theirs["rho_p01"].get<double>(), 1e-6) << "rho p01";
  EXPECT_EQ(rho["degenerate"], theirs["n_degenerate"]);
  EXPECT_EQ(ours["boundary_edges"], theirs["boundary_edges"]);
  EXPECT_EQ(ours["nonmanifold_edges"], theirs["nonmanifold_edges"]);
  EXPECT_EQ(ours["winding_errors"], theirs["orientation_errors"]);
  EXPECT_EQ(ours["euler"], theirs["euler"]);
  // Our "closed" also requires consistent winding; the script reports that separately.
  EXPECT_EQ(ours["closed"].get<bool>(),
            theirs["closed"].get<bool>() && theirs["orientation_errors"] == 0);
  // The script leaves these null without scipy (not a segmesh dependency).
  if (theirs["nonmanifold_vertices"].is_null() || theirs["components"].is_null()) {
    if (!scipy_note_printed) {
      std::printf(
          "note: mesh_metrics.py has no scipy here (Debian python3-scipy): non-manifold "
          "vertices and components are not compared\n");
      scipy_note_printed = true;
    }
    return;
  }
  EXPECT_EQ(ours["nonmanifold_vertices"], theirs["nonmanifold_vertices"]);
  EXPECT_EQ(ours["shells"], theirs["components"]);
}

// The phantom (the anatomy at 0.394 x 0.394 x 4 mm), written into the test's own folder: ctest
// runs the tests of this file as parallel processes.
fs::path small_phantom(const fs::path& dir) {
  const fs::path p = dir / "phantom.nii.gz";
  const auto r = run_segmesh("phantom -o " + q(p) + " --size 256,256,102 --spacing 0.394,0.394,4");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return p;
}

void mesh(const fs::path& phantom, const std::string& output) {
  const auto r = run_segmesh("mesh " + q(phantom) + " -o " + output + " --smooth none --quiet");  // unsmoothed: touching parts share surface points
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

TEST(QualityCli, AgreesWithMeshMetricsOnEveryFormat) {
  REQUIRE_MESH_METRICS(script);
  const fs::path dir = test::scratch_dir("quality_formats");
  const fs::path phantom = small_phantom(dir);
  for (const char* name : {"scene.stl", "scene.ply", "scene.obj", "scene.glb"}) {
    mesh(phantom, q(dir / name));
  }
  mesh(phantom, q(dir / "parts") + "/ --format ply");

  const std::vector<json> peer =
      mesh_metrics(script, {dir / "scene.stl", dir / "scene.ply", dir / "scene.obj"});
  ASSERT_EQ(peer.size(), 3u);
  const json stl = quality(dir / "scene.stl"), ply = quality(dir / "scene.ply"),
             obj = quality(dir / "scene.obj"), glb = quality(dir / "scene.glb");
  expect_agreement(stl["all"], peer[0], "scene.stl");
  expect_agreement(ply["all"], peer[1], "scene.ply");
  expect_agreement(obj["all"], peer[2], "scene.obj");
  // The script reads no glTF; the GLB holds the same float positions and indices as the PLY.
  expect_agreement(glb["all"], peer[1], "scene.glb against scene.ply");

  // The phantom's parts: 3 bone parts, the plate and 6 screws, each closed with one shell.
  for (const json* j : {&ply, &obj, &glb}) {
    ASSERT_EQ((*j)["parts"].size(), 10u) << (*j)["file"];
    EXPECT_EQ((*j)["all"]["parts"], 10);
    EXPECT_EQ((*j)["all"]["shells"], 10);
    EXPECT_TRUE((*j)["all"]["closed"].get<bool>());
    for (const json& part : (*j)["parts"]) {
      EXPECT_TRUE(part["closed"].get<bool>()) << part["name"];
      EXPECT_EQ(part["shells"], 1) << part["name"];
    }
  }
  // Binary STL is one solid, welded as a whole: the screws' surfaces share vertices (and edges,
  // used four times) with the bone where they touch, as the script sees the file too.
  ASSERT_EQ(stl["parts"].size(), 1u);
  EXPECT_GT(stl["all"]["nonmanifold_edges"].get<int64_t>(), 0);
  EXPECT_LT(stl["all"]["vertices"].get<int64_t>(), ply["all"]["vertices"].get<int64_t>());
  EXPECT_EQ(stl["all"]["triangles"], ply["all"]["triangles"]);

  // Per part: each part of scene.ply against the script on that part written alone.
  std::vector<fs::path> part_files;
  for (const json& part : ply["parts"]) {
    part_files.push_back(dir / "parts" / (part["name"].get<std::string>() + ".ply"));
    ASSERT_TRUE(fs::exists(part_files.back())) << part_files.back();
  }
  const std::vector<json> peer_parts = mesh_metrics(script, part_files);
  ASSERT_EQ(peer_parts.size(), part_files.size());
  for (size_t p = 0; p < part_files.size(); ++p) {
    expect_agreement(ply["parts"][p], peer_parts[p], part_files[p].filename().string());
    expect_agreement(glb["parts"][p], peer_parts[p], "glb " + part_files[p].filename().string());
    EXPECT_EQ(ply["parts"][p]["name"], glb["parts"][p]["name"]);
  }
  int64_t histogram_total = 0;
  for (const json& n : ply["all"]["radii_ratio"]["histogram"]) histogram_total += n.get<int64_t>();
  EXPECT_EQ(histogram_total, ply["all"]["triangles"].get<int64_t>());
}

// An OBJ with every defect the script counts, in one object with global indices (a quad fanned,
// a negative index, an unused vertex), and integer coordinates so both readers parse the same
// numbers: a cube with one triangle flipped, two tetrahedra sharing their tip, three triangles on
// one edge, a lone triangle, a collinear triangle and one that repeats a vertex.
const char* kDefectsObj = R"(# defects
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 0 0 1
v 1 0 1
v 0 1 1
v 1 1 1
f 1 3 2
f 2 4 3
f 1 2 6 5
f 3 7 8
f 3 8 4
f 1 5 7
f 1 7 3
f 2 4 8
f 2 8 6
f 5 6 8
f 5 8 7
v 10 0 0
v 9 -1 -1
v 9 1 -1
v 11 0 -1
v 9 -1 1
v 11 0 1
v 9 1 1
f 10 11 12
f 9 11 10
f 9 12 11
f 9 10 12
f 13 14 15
f 9 14 13
f 9 15 14
f 9 13 15
v 20 0 0
v 20 0 1
v 21 0 0
v 19 1 0
v 19 -1 0
f 16 17 18
f 17 16 19
f 16 17 -1
v 30 0 0
v 31 0 0
v 30 1 0
f 21 22 23
v 40 0 0
v 41 0 0
v 43 0 0
f 24 25 26
v 50 0 0
v 51 0 0
f 27 27 28
v 99 99 99
)";

// Two closed tetrahedra in two ASCII STL solids, glued on one face: each solid is closed, the file
// welded as a whole has the glued face twice and its three edges in four triangles each.
const char* kGluedStl = R"(solid lower
facet normal 0 0 0
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 1 0
endloop
endfacet
facet normal 0 0 0
outer loop
vertex 0 0 0
vertex 0 1 0
vertex 0 0 -1
endloop
endfacet
facet normal 0 0 0
outer loop
vertex 0 0 0
vertex 0 0 -1
vertex 1 0 0
endloop
endfacet
facet normal 0 0 0
outer loop
vertex 1 0 0
vertex 0 0 -1
vertex 0 1 0
endloop
endfacet
endsolid lower
solid upper
facet normal 0 0 0
outer loop
vertex 0 0 0
vertex 0 1 0
vertex 1 0 0
endloop
endfacet
facet normal 0 0 0
outer loop
vertex 0 0 0
vertex 0 0 1
vertex 0 1 0
endloop
endfacet
facet normal 0 0 0
outer loop
vertex 0 0 0
vertex 1 0 0
vertex 0 0 1
endloop
endfacet
facet normal 0 0 0
outer loop
vertex 1 0 0
vertex 0 1 0
vertex 0 0 1
endloop
endfacet
endsolid upper
)";

TEST(QualityCli, AgreesWithMeshMetricsOnDefectiveMeshes) {
  REQUIRE_MESH_METRICS(script);
  const fs::path dir = test::scratch_dir("quality_defects");
  std::ofstream(dir / "defects.obj") << kDefectsObj;
  std::ofstream(dir / "glued.stl") << kGluedStl;
  const std::vector<json> peer = mesh_metrics(script, {dir / "defects.obj", dir / "glued.stl"});
  ASSERT_EQ(peer.size(), 2u);

  const json obj = quality(dir / "defects.obj");
  expect_agreement(obj["all"], peer[0], "defects.obj");
  const json& d = obj["all"];
  EXPECT_EQ(d["winding_errors"], 3);        // the flipped cube triangle
  EXPECT_EQ(d["nonmanifold_vertices"], 2);  // the tetrahedra's tip, the repeated vertex
  EXPECT_EQ(d["nonmanifold_edges"], 1);     // the fin
  EXPECT_EQ(d["radii_ratio"]["degenerate"], 2);
  EXPECT_EQ(d["vertices"], 28);  // the unused vertex is not counted
  EXPECT_EQ(d["shells"], 6);
  EXPECT_FALSE(d["closed"].get<bool>());
  EXPECT_GT(d["boundary_edges"].get<int64_t>(), 0);

  const json stl = quality(dir / "glued.stl");
  expect_agreement(stl["all"], peer[1], "glued.stl");
  ASSERT_EQ(stl["parts"].size(), 2u);
  for (const json& part : stl["parts"]) {
    EXPECT_TRUE(part["closed"].get<bool>()) << part["name"];
    EXPECT_NEAR(part["volume_mm3"].get<double>(), 1.0 / 6, 1e-12) << part["name"];
  }
  EXPECT_EQ(stl["parts"][0]["name"], "lower");
  EXPECT_EQ(stl["all"]["vertices"], 5);  // welded across the solids
  EXPECT_EQ(stl["all"]["nonmanifold_edges"], 3);
  EXPECT_FALSE(stl["all"]["closed"].get<bool>());
  EXPECT_NEAR(stl["all"]["volume_mm3"].get<double>(), 1.0 / 3, 1e-12);
}

TEST(QualityCli, PrintsATablePerPartAndForAllParts) {
  const fs::path dir = test::scratch_dir("quality_table");
  const fs::path phantom = small_phantom(dir);
  mesh(phantom, q(dir / "scene.glb"));
  const auto r = run_segmesh("quality " + q(dir / "scene.glb"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* text : {"10 parts", "label1_1", "label2_7", "all parts", "rho_p01",
                           "nm_vertices", "closed", "histogram"}) {
    EXPECT_NE(r.out.find(text), std::string::npos) << text << " in\n" << r.out;
  }
  EXPECT_EQ(r.out.find("NO"), std::string::npos) << r.out;  // every part is closed
  const auto help = run_segmesh("--help");
  EXPECT_NE(help.out.find("quality"), std::string::npos) << help.out;
}

TEST(QualityCli, BadFilesGiveExitCode2AndOneLine) {
  const fs::path dir = test::scratch_dir("quality_bad");
  const fs::path phantom = small_phantom(dir);
  std::vector<fs::path> bad;
  for (const char* name : {"scene.stl", "scene.ply", "scene.glb"}) {
    mesh(phantom, q(dir / name));
    const fs::path truncated = dir / (std::string("truncated_") + name);
    fs::copy_file(dir / name, truncated);
    fs::resize_file(truncated, fs::file_size(truncated) / 2);
    bad.push_back(truncated);
  }
  std::ofstream(dir / "notes.txt") << "not a mesh\n";
  bad.push_back(dir / "notes.txt");
  bad.push_back(dir / "missing.ply");
  for (const fs::path& file : bad) {
    for (const char* json_flag : {"", " --json"}) {
      const auto r = run_segmesh("quality " + q(file) + json_flag);
      EXPECT_EQ(r.exit_code, 2) << file << ": " << r.err;
      EXPECT_EQ(r.err.rfind("segmesh: error: ", 0), 0u) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_NE(r.err.find(file.filename().string()), std::string::npos) << r.err;
      EXPECT_TRUE(r.out.empty()) << r.out;
    }
  }
  EXPECT_EQ(run_segmesh("quality").exit_code, 2);  // no file named
}

}  // namespace
}  // namespace segmesh
