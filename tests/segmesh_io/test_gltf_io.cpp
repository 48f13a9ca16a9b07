// GLB: writer structure, Khronos validator, round trip, foreign files, lying files.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "gltf_test_support.hpp"
#include "mesh_test_support.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;
using Json = nlohmann::json;

std::string make_glb(const Json& json, const std::string& bin) {
  std::string j = json.dump();
  while (j.size() % 4) j.push_back(' ');
  std::string b = bin;
  while (b.size() % 4) b.push_back('\0');
  std::string out;
  const auto put = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  put(0x46546C67), put(2), put(uint32_t(12 + 8 + j.size() + (b.empty() ? 0 : 8 + b.size())));
  put(uint32_t(j.size())), put(0x4E4F534A);
  out += j;
  if (!b.empty()) {
    put(uint32_t(b.size())), put(0x004E4942);
    out += b;
  }
  return out;
}

// A scene with everything the writer can put in a GLB: normals, colours, a moved part, a hidden
// part, an empty part.
Scene rich_scene() {
  Scene scene = two_part_scene();
  for (size_t v = 0; v < 8; ++v) scene.parts[0].mesh.colors.push_back({uint8_t(v * 31), 100, 200, 255});
  scene.parts[1].transform = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 10.5, -20, 30.25, 1};
  scene.parts[1].visible = false;
  scene.parts[1].mesh.normals = {{0, 0, 2}, {0, 0, 0}, {1, 1, 0}, {0.5f, 0, 0}};  // not unit
  scene.parts.push_back(make_part("empty", 5, Role::other, TriMesh{}));
  Part third = make_part("screw", 3, Role::implant, tetrahedron());
  scene.parts.push_back(third);
  return scene;
}

TEST(GlbTest, PassesTheKhronosValidatorWithoutErrorsOrWarnings) {
  const fs::path dir = scratch_dir("glb_validator");
  write_scene(rich_scene(), dir / "rich.glb", MeshFormat::glb);
  Scene plain;
  plain.parts.push_back(make_part("tet", 1, Role::bone, tetrahedron()));  // no normals, no colours
  write_scene(plain, dir / "plain.glb", MeshFormat::glb);
  write_parts(rich_scene(), dir / "parts", MeshFormat::glb);
  Scene empty;
  write_scene(empty, dir / "empty.glb", MeshFormat::glb);
  for (const fs::path& file : {dir / "rich.glb", dir / "plain.glb", dir / "parts" / "screw.glb", dir / "empty.glb"}) {
    expect_valid_glb(file);
  }
}

TEST(GlbTest, RootNodeMapsLpsMillimetresToGltf) {
  const fs::path dir = scratch_dir("glb_structure");
  const Scene scene = rich_scene();
  write_scene(scene, dir / "scene.glb", MeshFormat::glb);
  const std::string bytes = read_bytes(dir / "scene.glb");
  ASSERT_EQ(u32(bytes, 0), 0x46546C67u);
  EXPECT_EQ(u32(bytes, 8), bytes.size());
  const Glb g = split_glb(bytes);
  const Json& j = g.json;
  EXPECT_EQ(j["asset"]["version"], "2.0");
  EXPECT_EQ(j["asset"]["generator"], "segmesh");
  EXPECT_EQ(j["asset"]["extras"]["units"], "mm");
  EXPECT_EQ(j["asset"]["extras"]["space"], "LPS");
  EXPECT_TRUE(j["asset"]["extras"]["root_transform"].is_string());
  EXPECT_EQ(j["scenes"][0]["nodes"], Json::array({0}));
  const Json& root = j["nodes"][0];
  EXPECT_EQ(root["name"], "segmesh_scene");
  EXPECT_EQ(root["matrix"], Json::array({0.001, 0, 0, 0, 0, 0, -0.001, 0, 0, 0.001, 0, 0, 0, 0, 0, 1}));
  // LPS (x, y, z) = (1, 2, 3) mm lands at glTF (x, z, -y) metres.
  std::array<double, 3> lps{1, 2, 3}, gltf{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) gltf[r] += root["matrix"][4 * c + r].get<double>() * lps[c];
  }
  EXPECT_DOUBLE_EQ(gltf[0], 0.001);
  EXPECT_DOUBLE_EQ(gltf[1], 0.003);
  EXPECT_DOUBLE_EQ(gltf[2], -0.002);

  ASSERT_EQ(root["children"].size(), 3u);  // the empty part is skipped
  const Json& tibia = j["nodes"][root["children"][0].get<int>()];
  const Json& plate = j["nodes"][root["children"][1].get<int>()];
  EXPECT_EQ(tibia["name"], "tibia");
  EXPECT_FALSE(tibia.contains("matrix"));  // identity transforms are left out
  EXPECT_EQ(tibia["extras"]["label"], 1);
  EXPECT_EQ(tibia["extras"]["role"], "bone");
  EXPECT_EQ(tibia["extras"]["voxels"], 1001);
  EXPECT_EQ(tibia["extras"]["visible"], true);
  EXPECT_EQ(plate["extras"]["visible"], false);
  EXPECT_EQ(plate["matrix"][12], 10.5);
  const Json& prim = j["meshes"][tibia["mesh"].get<int>()]["primitives"][0];
  EXPECT_TRUE(prim["attributes"].contains("NORMAL"));
  EXPECT_TRUE(prim["attributes"].contains("COLOR_0"));
  const Json& pos = j["accessors"][prim["attributes"]["POSITION"].get<int>()];
  EXPECT_EQ(pos["min"][0].get<double>(), double(-3.3f));
  EXPECT_EQ(pos["max"][1].get<double>(), double(1 * 20.7f + 0.1f));
  EXPECT_EQ(j["accessors"][prim["indices"].get<int>()]["componentType"], 5125);
  const Json& tibia_mat = j["materials"][prim["material"].get<int>()];
  EXPECT_EQ(tibia_mat["name"], "tibia");
  EXPECT_EQ(tibia_mat["pbrMetallicRoughness"]["metallicFactor"], 0.0);
  const Json& plate_mat = j["materials"][j["meshes"][plate["mesh"].get<int>()]["primitives"][0]["material"].get<int>()];
  EXPECT_EQ(plate_mat["pbrMetallicRoughness"]["metallicFactor"], 1.0);
  EXPECT_EQ(plate_mat["pbrMetallicRoughness"]["roughnessFactor"], 0.7);
  EXPECT_EQ(plate_mat["pbrMetallicRoughness"]["baseColorFactor"], Json::array({0.8, 0.05, 0.05, 1.0}));
}

TEST(GlbTest, RoundTripKeepsNamesMaterialsTransformsAndData) {
  const fs::path dir = scratch_dir("glb_round_trip");
  const Scene scene = rich_scene();
  write_scene(scene, dir / "scene.glb", MeshFormat::glb);
  const Scene back = read_mesh(dir / "scene.glb");
  ASSERT_EQ(back.parts.size(), 3u);
  const size_t source[] = {0, 1, 3};
  for (size_t i = 0; i < 3; ++i) {
    const Part& a = scene.parts[source[i]];
    const Part& b = back.parts[i];
    SCOPED_TRACE(a.name);
    expect_same_part_info(b, a);
    EXPECT_EQ(b.voxel_volume_mm3, a.voxel_volume_mm3);
    EXPECT_EQ(b.transform, a.transform);  // relative to the root, bit for bit
    EXPECT_EQ(b.mesh.indices, a.mesh.indices);
    EXPECT_EQ(b.mesh.colors, a.mesh.colors);
    ASSERT_EQ(b.mesh.vertex_count(), a.mesh.vertex_count());
    ASSERT_EQ(b.mesh.normals.size(), a.mesh.normals.size());
    for (size_t v = 0; v < a.mesh.vertex_count(); ++v) {
      EXPECT_TRUE(same(b.mesh.positions[v], a.mesh.positions[v]));
      if (a.mesh.normals.empty()) continue;
      EXPECT_NEAR(norm(to_double(b.mesh.normals[v])), 1.0, 1e-6);  // written unit length
    }
  }
  EXPECT_TRUE(same(back.parts[0].mesh.normals[7], scene.parts[0].mesh.normals[7]));  // unit already
  EXPECT_TRUE(same(back.parts[1].mesh.normals[0], Vec3f{0, 0, 1}));                  // (0, 0, 2) scaled
  // A zero normal is replaced by its vertex's area-weighted face normal: vertex 1 of the tet
  // touches the faces with normals -y, -z and (1,1,1)/sqrt(3).
  const Vec3f n1 = back.parts[1].mesh.normals[1];
  EXPECT_GT(n1.x, 0);
  EXPECT_LT(n1.z, n1.x);
}

TEST(GlbTest, NamesThatAreNotUtf8AreRepairedNotFatal) {
  const fs::path dir = scratch_dir("glb_latin1");
  Scene scene;
  scene.parts.push_back(make_part("f\xe9mur", 1, Role::bone, tetrahedron()));  // Latin-1 e-acute
  write_scene(scene, dir / "latin1.glb", MeshFormat::glb);
  EXPECT_EQ(read_mesh(dir / "latin1.glb").parts.at(0).name, "f\xef\xbf\xbdmur");  // U+FFFD
}

// Many parts (an automatic segmenter's or a random label map's): the file is valid, plain and
// quantized, and every part reads back with its own name, label, component, role, voxels, volume,
// visibility and material, in order; names that need JSON escaping survive.
TEST(GlbTest, ManyPartsAreValidAndReadBackInOrder) {
  const fs::path dir = scratch_dir("glb_many_parts");
  Scene scene;
  const char* awkward[] = {"quote\"d", "back\\slash", "new\nline", "tab\tbed", "caf\xc3\xa9", "\x01ctl", "/slash/"};
  constexpr int kParts = 2500;
  for (int i = 0; i < kParts; ++i) {
    TriMesh tet = tetrahedron();
    for (Vec3f& p : tet.positions) p = {p.x + float(i % 50) * 3, p.y + float(i / 50) * 3, p.z + 0.5f * float(i % 7)};
    const std::string name = "part" + std::to_string(i) + (i % 100 == 0 ? awkward[(i / 100) % 7] : "");
    Part part = make_part(name, 1 + i % 255, i % 3 ? Role::bone : Role::implant, std::move(tet));
    part.component = 1 + i / 255;
    part.visible = i % 11 != 0;
    scene.parts.push_back(std::move(part));
  }
  for (const bool quantize : {false, true}) {
    SCOPED_TRACE(quantize);
    const fs::path file = dir / (quantize ? "many_q.glb" : "many.glb");
    write_scene(scene, file, MeshFormat::glb, {.quantize = quantize});
    expect_valid_glb(file);
    const Scene back = read_mesh(file);
    ASSERT_EQ(back.parts.size(), size_t(kParts));
    for (int i = 0; i < kParts; ++i) {
      const Part& a = scene.parts[size_t(i)];
      const Part& b = back.parts[size_t(i)];
      ASSERT_EQ(b.name, a.name) << i;
      expect_same_part_info(b, a);
      EXPECT_EQ(b.voxel_volume_mm3, a.voxel_volume_mm3);
      EXPECT_EQ(b.mesh.indices, a.mesh.indices);
      ASSERT_EQ(b.mesh.vertex_count(), a.mesh.vertex_count());
      for (size_t v = 0; v < a.mesh.vertex_count(); ++v) {
        EXPECT_LE(norm(to_double(b.mesh.positions[v]) - to_double(a.mesh.positions[v])), quantize ? 2e-3 : 0.0);
      }
    }
  }
}

// A file in glTF's own convention (metres, +Y up), not made by segmesh: u16 indices, TRS node
// inside a parent, no material. Its coordinates are converted to LPS millimetres.
TEST(GlbTest, ReadsForeignFilesAndConvertsMetresToLpsMillimetres) {
  const fs::path dir = scratch_dir("glb_foreign");
  std::string bin;
  const float pos[] = {0, 0, 0, 0.001f, 0, 0, 0, 0.002f, 0};
  bin.append(reinterpret_cast<const char*>(pos), sizeof pos);
  const uint16_t idx[] = {0, 1, 2, 0};  // padded to 4 bytes
  bin.append(reinterpret_cast<const char*>(idx), sizeof idx);
  Json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"children", {1}}, {"translation", {0.01, 0, 0}}},
                 {{"mesh", 0}, {"rotation", {0, 0, 0, 1}}}}},
      {"meshes", {{{"name", "tri"}, {"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"},
                      {"min", {0, 0, 0}}, {"max", {0.001, 0.002, 0}}},
                     {{"bufferView", 1}, {"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                       {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 6}}}},
      {"buffers", {{{"byteLength", bin.size()}}}}};
  write_bytes(dir / "foreign.glb", make_glb(j, bin));
  const Scene s = read_mesh(dir / "foreign.glb");
  ASSERT_EQ(s.parts.size(), 1u);
  EXPECT_EQ(s.parts[0].name, "tri");
  EXPECT_EQ(s.parts[0].transform, identity_transform());  // the scale 1000 is baked
  const TriMesh& m = s.parts[0].mesh;
  ASSERT_EQ(m.vertex_count(), 3u);
  // glTF (x, y, z) m -> LPS (x, -z, y) mm.
  EXPECT_NEAR(m.positions[0].x, 10, 1e-4);
  EXPECT_NEAR(m.positions[1].x, 11, 1e-4);
  EXPECT_NEAR(m.positions[2].z, 2, 1e-4);
  EXPECT_NEAR(m.positions[2].y, 0, 1e-4);
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));

  // Without indices, and without scenes: triangles are consecutive vertices.
  j.erase("scene");
  j.erase("scenes");
  j["meshes"][0]["primitives"][0].erase("indices");
  j["accessors"].erase(1);
  j["bufferViews"].erase(1);
  write_bytes(dir / "unindexed.glb", make_glb(j, bin));
  EXPECT_EQ(read_mesh(dir / "unindexed.glb").parts.at(0).mesh.indices, (std::vector<uint32_t>{0, 1, 2}));
}

TEST(GlbTest, TruncatedLyingAndUnsupportedFilesAreErrors) {
  const fs::path dir = scratch_dir("glb_lying");
  write_scene(two_part_scene(), dir / "good.glb", MeshFormat::glb);
  const std::string good = read_bytes(dir / "good.glb");
  const Glb g = split_glb(good);
  const auto check = [&](const std::string& name, const std::string& bytes, const char* expect) {
    write_bytes(dir / name, bytes);
    const std::string msg = error_message([&] { read_mesh(dir / name); }, dir / name);
    EXPECT_NE(msg.find(expect), std::string::npos) << msg;
  };
  check("truncated.glb", good.substr(0, good.size() / 2), "truncated");
  check("tiny.glb", good.substr(0, 10), "truncated");

  std::string bad_chunk = good;
  const uint32_t huge = 0x7FFFFFF0;
  std::memcpy(bad_chunk.data() + 12, &huge, 4);
  check("bad_chunk.glb", bad_chunk, "truncated");

  const auto edited = [&](auto edit) {
    Json j = g.json;
    edit(j);
    return make_glb(j, g.bin);
  };
  check("lying_count.glb", edited([](Json& j) { j["accessors"][0]["count"] = 1000000000; }), "more than its bufferView");
  check("lying_view.glb", edited([](Json& j) { j["bufferViews"][0]["byteLength"] = 1u << 30; }), "outside");
  check("bad_index.glb", [&] {
    std::string b = g.bin;
    const int indices = g.json["meshes"][0]["primitives"][0]["indices"];
    const size_t at = g.json["bufferViews"][g.json["accessors"][indices]["bufferView"].get<int>()]["byteOffset"];
    const uint32_t nine = 9;
    std::memcpy(b.data() + at, &nine, 4);
    return make_glb(g.json, b);
  }(), "index 9 is out of range");
  check("bad_accessor_ref.glb", edited([](Json& j) { j["meshes"][0]["primitives"][0]["indices"] = 99; }), "out of range");
  check("cycle.glb", edited([](Json& j) { j["nodes"][1]["children"] = {0}; }), "twice");
  check("lines.glb", edited([](Json& j) { j["meshes"][0]["primitives"][0]["mode"] = 1; }), "mode 1");
  check("sparse.glb", edited([](Json& j) { j["accessors"][0]["sparse"] = Json::object(); }), "sparse");
  check("draco.glb", edited([](Json& j) { j["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }), "KHR_draco_mesh_compression");
  check("external.glb", edited([](Json& j) { j["buffers"][0]["uri"] = "data.bin"; }), "external");
  check("wrong_type.glb", edited([](Json& j) { j["nodes"] = "nodes"; }), "not an array");
  check("bad_json.glb", [&] {
    std::string b = good;
    b[20] = '[';
    return b;
  }(), "not valid JSON");
  check("text.glb", "{\"asset\": {\"version\": \"2.0\"}}", "text glTF");
}

}  // namespace
}  // namespace segmesh
