// Quantized GLB (MeshWriteOptions::quantize, KHR_mesh_quantization): valid under the Khronos
// validator, read back within the grid's rounding, contacts still shared, smaller; refused for
// other formats.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <tuple>

#include "gltf_test_support.hpp"
#include "mesh_test_support.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;

// The touching boxes meshed with the defaults: conforming surfaces, so parts share the vertices
// of their contacts.
Scene touching_scene() { return build_scene(touching_boxes(true), MeshingOptions{}); }

// The largest extent of all positions: the grid step is this / 65535.
double largest_extent(const Scene& scene) {
  Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (const Part& part : scene.parts) {
    for (const Vec3f& p : part.mesh.positions) {
      lo = {std::min(lo.x, double(p.x)), std::min(lo.y, double(p.y)), std::min(lo.z, double(p.z))};
      hi = {std::max(hi.x, double(p.x)), std::max(hi.y, double(p.y)), std::max(hi.z, double(p.z))};
    }
  }
  return std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
}

TEST(GlbQuantization, IsValidAndUsesTheExtension) {
  const fs::path dir = scratch_dir("glb_quantized_valid");
  write_scene(touching_scene(), dir / "scene.glb", MeshFormat::glb, {.quantize = true});
  expect_valid_glb(dir / "scene.glb");

  const Glb glb = split_glb(read_bytes(dir / "scene.glb"));
  EXPECT_EQ(glb.json["extensionsRequired"], nlohmann::json::array({"KHR_mesh_quantization"}));
  EXPECT_EQ(glb.json["extensionsUsed"], nlohmann::json::array({"KHR_mesh_quantization"}));
  const nlohmann::json& accessors = glb.json["accessors"];
  const nlohmann::json& primitive = glb.json["meshes"][0]["primitives"][0];
  EXPECT_EQ(accessors[primitive["attributes"]["POSITION"].get<int>()]["componentType"], 5123);
  EXPECT_EQ(accessors[primitive["attributes"]["NORMAL"].get<int>()]["componentType"], 5120);
  EXPECT_EQ(accessors[primitive["indices"].get<int>()]["componentType"], 5123);  // small parts
  // Per-part files are quantized too, each on its own grid, and valid.
  const std::vector<fs::path> files =
      write_parts(touching_scene(), dir / "parts", MeshFormat::glb, {.quantize = true});
  ASSERT_FALSE(files.empty());
  expect_valid_glb(files.front());
}

TEST(GlbQuantization, ReadsBackWithinHalfAGridStepAndKeepsContactsShared) {
  const fs::path dir = scratch_dir("glb_quantized_round_trip");
  const Scene scene = touching_scene();
  ASSERT_EQ(scene.parts.size(), 3u);
  write_scene(scene, dir / "scene.glb", MeshFormat::glb, {.quantize = true});
  const Scene back = read_mesh(dir / "scene.glb");
  ASSERT_EQ(back.parts.size(), scene.parts.size());

  const double step = largest_extent(scene) / 65535.0;
  const double bound = std::sqrt(3.0) / 2 * step + 1e-5;  // plus float rounding of mm values
  // Each original position -> where it came back, over all parts: a contact vertex (one position
  // in two parts) must come back at one position too.
  std::map<std::tuple<float, float, float>, Vec3f> returned;
  size_t shared = 0;
  for (size_t p = 0; p < scene.parts.size(); ++p) {
    const TriMesh& a = scene.parts[p].mesh;
    const TriMesh& b = back.parts[p].mesh;
    SCOPED_TRACE(scene.parts[p].name);
    EXPECT_EQ(back.parts[p].name, scene.parts[p].name);
    EXPECT_EQ(b.indices, a.indices);
    ASSERT_EQ(b.positions.size(), a.positions.size());
    ASSERT_EQ(b.normals.size(), a.normals.size());
    double worst = 0, worst_turn = 0;
    for (size_t v = 0; v < a.positions.size(); ++v) {
      worst = std::max(worst, norm(to_double(b.positions[v]) - to_double(a.positions[v])));
      const Vec3d na = to_double(a.normals[v]), nb = to_double(b.normals[v]);
      worst_turn = std::max(worst_turn, std::acos(std::clamp(dot(na, nb) / (norm(na) * norm(nb)), -1.0, 1.0)));
      const auto key = std::make_tuple(a.positions[v].x, a.positions[v].y, a.positions[v].z);
      const auto [it, fresh] = returned.emplace(key, b.positions[v]);
      if (!fresh) {
        ++shared;
        EXPECT_TRUE(same(it->second, b.positions[v])) << "a shared vertex came back at two places";
      }
    }
    EXPECT_LE(worst, bound);
    EXPECT_GT(worst, 0.0);  // quantized, not written as floats
    EXPECT_LT(worst_turn * 180 / M_PI, 1.0);  // 8-bit normals: under a degree
    EXPECT_TRUE(closed_and_oriented(b));
  }
  EXPECT_GT(shared, 100u);  // the contacts were there to test
}

TEST(GlbQuantization, IsSmallerThanFloatGlb) {
  const fs::path dir = scratch_dir("glb_quantized_size");
  const Scene scene = touching_scene();
  write_scene(scene, dir / "float.glb", MeshFormat::glb);
  write_scene(scene, dir / "quantized.glb", MeshFormat::glb, {.quantize = true});
  // Per vertex 24 -> 12 bytes, per triangle 12 -> 6 (parts under 65536 vertices).
  EXPECT_LT(double(fs::file_size(dir / "quantized.glb")), 0.6 * double(fs::file_size(dir / "float.glb")));
}

TEST(GlbQuantization, OtherFormatsAreRefusedWithNothingWritten) {
  const fs::path dir = scratch_dir("glb_quantized_refused");
  const Scene scene = touching_scene();
  for (MeshFormat format : {MeshFormat::ply, MeshFormat::stl, MeshFormat::obj}) {
    const fs::path file = dir / ("scene." + std::string(extension(format)));
    const std::string message = error_message([&] { write_scene(scene, file, format, {.quantize = true}); }, file);
    EXPECT_NE(message.find("write glb"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(file));
  }
  EXPECT_TRUE(list_dir(dir).empty());
}

}  // namespace
}  // namespace segmesh
