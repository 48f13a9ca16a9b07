// Atlas export (atlas_writer.hpp): the conforming surface of a scene built with --surfaces
// conforming, written as PLY and GLB, read back and compared with the surface (or, where no parts
// touch, with the parts' shells); the errors.
#include "segmesh_io/atlas_writer.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "gltf_test_support.hpp"
#include "mesh_test_support.hpp"
#include "segmesh/pipeline.hpp"
#include "segmesh_io/gltf_writer.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;
using Sides = std::array<uint32_t, 2>;

Scene scene_of(bool touching, Surfaces surfaces) {
  MeshingOptions o;
  o.surfaces = surfaces;
  o.label_names = {{1, "block", {}, {}}, {2, "left block", {}, {}}, {3, "cap", {}, {}}};
  return build_scene(touching_boxes(touching), o);
}

// The touching boxes with a conforming surface, checked to be worth testing on (three parts,
// contacts between parts, junction edges with three or more triangles), written as
// "atlas.<extension>" into a fresh folder.
struct WrittenAtlas {
  Scene scene;
  fs::path file;
};
WrittenAtlas write_touching_atlas(const std::string& extension) {
  WrittenAtlas w{scene_of(true, Surfaces::conforming),
                 scratch_dir("atlas_" + extension) / ("atlas." + extension)};
  EXPECT_EQ(w.scene.parts.size(), 3u);
  if (!w.scene.surface) {
    ADD_FAILURE() << "build_scene made no conforming surface";
    return w;
  }
  const LabelledSurface& s = *w.scene.surface;
  size_t between_parts = 0;
  for (const Sides& pair : s.sides) between_parts += pair[0] != 0 && pair[1] != 0;
  EXPECT_GT(between_parts, 0u);
  size_t junction_edges = 0;
  for (const auto& [edge, uses] : edge_uses(s.mesh)) junction_edges += uses >= 3;
  EXPECT_GT(junction_edges, 0u);
  write_atlas(w.scene, w.file);
  return w;
}

std::string material_name(const Scene& scene, uint32_t m) {
  return m == 0 ? std::string("background") : scene.parts[m - 1].name;
}

// An atlas PLY parsed by the element counts its header states.
struct AtlasPly {
  std::vector<std::string> comments;   // the "comment material ..." lines
  std::vector<std::string> structure;  // the header lines that are not comments
  std::vector<Vec3f> positions;
  std::vector<uint32_t> indices;
  std::vector<Sides> sides;
  size_t non_triangles = 0;
  size_t bytes_after_faces = 0;
};

AtlasPly read_atlas_ply(const fs::path& file) {
  AtlasPly ply;
  const std::string bytes = read_bytes(file);
  const size_t end = bytes.find("end_header\n");
  if (end == std::string::npos) {
    ADD_FAILURE() << file << " has no end_header line";
    return ply;
  }
  size_t vertices = 0, faces = 0;
  std::istringstream lines(bytes.substr(0, end));
  for (std::string line; std::getline(lines, line);) {
    if (line.starts_with("comment material ")) ply.comments.push_back(line);
    if (line.starts_with("comment ")) continue;
    ply.structure.push_back(line);
    if (line.starts_with("element vertex ")) vertices = std::stoul(line.substr(15));
    if (line.starts_with("element face ")) faces = std::stoul(line.substr(13));
  }
  size_t at = end + std::strlen("end_header\n");
  if (bytes.size() < at + 12 * vertices + 21 * faces) {
    ADD_FAILURE() << file << " is shorter than its header says";
    return ply;
  }
  ply.positions.resize(vertices);
  std::memcpy(ply.positions.data(), bytes.data() + at, 12 * vertices);
  at += 12 * vertices;
  for (size_t t = 0; t < faces; ++t, at += 21) {
    int32_t v[5];
    std::memcpy(v, bytes.data() + at + 1, sizeof v);
    ply.non_triangles += bytes[at] != 3;
    ply.indices.insert(ply.indices.end(), {uint32_t(v[0]), uint32_t(v[1]), uint32_t(v[2])});
    ply.sides.push_back({uint32_t(v[3]), uint32_t(v[4])});
  }
  ply.bytes_after_faces = bytes.size() - at;
  return ply;
}

std::vector<std::string> material_comments(const Scene& scene) {
  std::vector<std::string> lines;
  for (uint32_t m = 0; m <= scene.parts.size(); ++m) {
    lines.push_back("comment material " + std::to_string(m) + " " + material_name(scene, m));
  }
  return lines;
}

std::vector<std::string> ply_structure(size_t vertices, size_t faces) {
  return {"ply", "format binary_little_endian 1.0", "element vertex " + std::to_string(vertices),
          "property float x", "property float y", "property float z",
          "element face " + std::to_string(faces), "property list uchar int vertex_indices",
          "property int inside", "property int outside"};
}

bool same_positions(const std::vector<Vec3f>& a, const Vec3f* b, size_t count) {
  return a.size() >= count && std::memcmp(a.data(), b, 12 * count) == 0;
}

// An atlas GLB: its JSON, the bytes of its first POSITION accessor and its primitives.
struct AtlasPrimitive {
  Sides pair;
  nlohmann::json extras, attributes;
  std::vector<uint32_t> indices;
};
struct AtlasGlb {
  nlohmann::json json;
  std::string positions;
  std::vector<AtlasPrimitive> primitives;
};

AtlasGlb read_atlas_glb(const fs::path& file) {
  expect_valid_glb(file);
  const Glb g = split_glb(read_bytes(file));
  AtlasGlb atlas{g.json, {}, {}};
  const nlohmann::json& j = g.json;
  const auto view_bytes = [&](size_t accessor) {
    const nlohmann::json& view = j["bufferViews"][j["accessors"][accessor]["bufferView"].get<size_t>()];
    return g.bin.substr(view["byteOffset"].get<size_t>(), view["byteLength"].get<size_t>());
  };
  if (j["meshes"].size() != 1) {
    ADD_FAILURE() << file << " has " << j["meshes"].size() << " meshes, not one";
    return atlas;
  }
  for (const nlohmann::json& p : j["meshes"][0]["primitives"]) {
    AtlasPrimitive primitive{{p["extras"]["inside_material"].get<uint32_t>(),
                              p["extras"]["outside_material"].get<uint32_t>()},
                             p["extras"], p["attributes"], {}};
    const std::string index_bytes = view_bytes(p["indices"].get<size_t>());
    primitive.indices.resize(index_bytes.size() / 4);
    std::memcpy(primitive.indices.data(), index_bytes.data(), index_bytes.size());
    atlas.primitives.push_back(std::move(primitive));
  }
  atlas.positions = view_bytes(j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<size_t>());
  return atlas;
}

TEST(AtlasWriter, PlyHoldsTheSurfaceAndEveryTrianglesMaterials) {
  const auto [scene, file] = write_touching_atlas("ply");
  ASSERT_TRUE(scene.surface);
  const LabelledSurface& s = *scene.surface;
  const AtlasPly ply = read_atlas_ply(file);
  EXPECT_EQ(ply.comments, (std::vector<std::string>{"comment material 0 background",
                                                    "comment material 1 block_1",
                                                    "comment material 2 left block_1",
                                                    "comment material 3 cap_1"}));
  EXPECT_EQ(ply.structure, ply_structure(s.mesh.vertex_count(), s.mesh.triangle_count()));
  EXPECT_EQ(ply.bytes_after_faces, 0u);
  EXPECT_EQ(ply.non_triangles, 0u);
  ASSERT_EQ(ply.positions.size(), s.mesh.vertex_count());
  EXPECT_TRUE(same_positions(ply.positions, s.mesh.positions.data(), s.mesh.vertex_count()));
  EXPECT_TRUE(ply.indices == s.mesh.indices);
  EXPECT_TRUE(ply.sides == s.sides);

  // Other PLY readers see the geometry: the project's own reader skips inside and outside.
  const Scene back = read_mesh(file);
  ASSERT_EQ(back.parts.size(), 1u);
  EXPECT_TRUE(back.parts[0].mesh.indices == s.mesh.indices);
  EXPECT_TRUE(same_positions(back.parts[0].mesh.positions, s.mesh.positions.data(), s.mesh.vertex_count()));
}

TEST(AtlasWriter, GlbHasAPrimitivePerMaterialPairOverSharedPositions) {
  const auto [scene, file] = write_touching_atlas("glb");
  ASSERT_TRUE(scene.surface);
  const LabelledSurface& s = *scene.surface;
  const AtlasGlb glb = read_atlas_glb(file);

  // The root node converts LPS millimetres as every segmesh GLB does.
  const nlohmann::json& root = glb.json["nodes"][0];
  EXPECT_EQ(root["name"], kGltfRootName);
  ASSERT_EQ(root["matrix"].size(), 16u);
  for (size_t k = 0; k < 16; ++k) EXPECT_EQ(root["matrix"][k].get<double>(), kGltfRootMatrix[k]);
  EXPECT_EQ(root["children"], nlohmann::json::array({1}));
  // One POSITION accessor for all primitives: the surface's positions bit for bit.
  ASSERT_EQ(glb.positions.size(), 12 * s.mesh.vertex_count());
  EXPECT_EQ(std::memcmp(glb.positions.data(), s.mesh.positions.data(), glb.positions.size()), 0);

  // A primitive per pair, holding exactly the surface's triangles of that pair in surface order.
  std::map<Sides, std::vector<uint32_t>> expected;
  for (size_t t = 0; t < s.sides.size(); ++t) {
    std::vector<uint32_t>& tri = expected[s.sides[t]];
    tri.insert(tri.end(), s.mesh.indices.begin() + 3 * t, s.mesh.indices.begin() + 3 * t + 3);
  }
  EXPECT_EQ(glb.primitives.size(), expected.size());
  std::set<Sides> seen;
  size_t triangles = 0;
  for (const AtlasPrimitive& p : glb.primitives) {
    SCOPED_TRACE(std::to_string(p.pair[0]) + "|" + std::to_string(p.pair[1]));
    EXPECT_TRUE(seen.insert(p.pair).second) << "two primitives of one pair";
    EXPECT_EQ(p.attributes, glb.json["meshes"][0]["primitives"][0]["attributes"]);
    EXPECT_EQ(p.attributes.size(), 1u);
    EXPECT_EQ(p.extras["inside"], material_name(scene, p.pair[0]));
    EXPECT_EQ(p.extras["outside"], material_name(scene, p.pair[1]));
    EXPECT_TRUE(p.indices == expected[p.pair]);
    triangles += p.indices.size() / 3;
  }
  EXPECT_EQ(triangles, s.mesh.triangle_count());
}

// Conforming surfaces on parts that touch nowhere have no Scene::surface (each part was meshed on
// its own, the same surfaces): the atlas is every part's shell against the background.
TEST(AtlasWriter, PartsThatTouchNowhereGiveTheirShellsAgainstTheBackground) {
  const Scene scene = scene_of(false, Surfaces::conforming);
  ASSERT_TRUE(scene.conforming);
  ASSERT_FALSE(scene.surface);
  ASSERT_EQ(scene.parts.size(), 2u);
  const fs::path dir = scratch_dir("atlas_apart");
  write_atlas(scene, dir / "atlas.ply");
  write_atlas(scene, dir / "atlas.glb");
  const AtlasPly ply = read_atlas_ply(dir / "atlas.ply");
  const AtlasGlb glb = read_atlas_glb(dir / "atlas.glb");
  EXPECT_EQ(ply.comments, material_comments(scene));
  const size_t vertices = scene.parts[0].mesh.vertex_count() + scene.parts[1].mesh.vertex_count();
  const size_t triangles = scene.parts[0].mesh.triangle_count() + scene.parts[1].mesh.triangle_count();
  EXPECT_EQ(ply.structure, ply_structure(vertices, triangles));
  ASSERT_EQ(ply.positions.size(), vertices);
  ASSERT_EQ(ply.sides.size(), triangles);
  ASSERT_EQ(glb.primitives.size(), 2u);
  ASSERT_EQ(glb.positions.size(), 12 * vertices);
  uint32_t first = 0;
  size_t t0 = 0;
  for (uint32_t p = 0; p < 2; ++p) {
    SCOPED_TRACE(scene.parts[p].name);
    const TriMesh& m = scene.parts[p].mesh;
    std::vector<uint32_t> shifted(m.indices);
    for (uint32_t& i : shifted) i += first;
    EXPECT_EQ(std::memcmp(ply.positions.data() + first, m.positions.data(), 12 * m.vertex_count()), 0);
    EXPECT_EQ(std::memcmp(glb.positions.data() + 12 * first, m.positions.data(), 12 * m.vertex_count()), 0);
    EXPECT_TRUE(std::equal(shifted.begin(), shifted.end(), ply.indices.begin() + 3 * t0));
    EXPECT_EQ(std::count(ply.sides.begin() + t0, ply.sides.begin() + t0 + m.triangle_count(), Sides{p + 1, 0}),
              m.triangle_count());
    EXPECT_EQ(glb.primitives[p].pair, (Sides{p + 1, 0}));
    EXPECT_EQ(glb.primitives[p].extras["inside"], scene.parts[p].name);
    EXPECT_TRUE(glb.primitives[p].indices == shifted);
    first += uint32_t(m.vertex_count());
    t0 += m.triangle_count();
  }
}

TEST(AtlasWriter, RefusesIndependentSurfacesOrABadExtensionAndLeavesNothing) {
  const fs::path dir = scratch_dir("atlas_errors");
  const Scene plain = scene_of(true, Surfaces::independent);
  ASSERT_FALSE(plain.surface);
  std::string msg = error_message([&] { write_atlas(plain, dir / "a.ply"); }, dir / "a.ply");
  EXPECT_NE(msg.find("--atlas needs --surfaces conforming"), std::string::npos) << msg;

  const Scene scene = scene_of(true, Surfaces::conforming);
  for (const char* bad : {"a.stl", "a.obj", "a", "a.ply.gz"}) {
    msg = error_message([&] { write_atlas(scene, dir / bad); }, dir / bad);
    EXPECT_NE(msg.find(".ply or .glb"), std::string::npos) << msg;
  }
  msg = error_message([&] { write_atlas(scene, dir / "missing" / "a.glb"); }, dir / "missing" / "a.glb");
  EXPECT_TRUE(list_dir(dir).empty());

  // A failed write leaves an earlier atlas as it was.
  write_atlas(scene, dir / "a.glb");
  const std::string before = read_bytes(dir / "a.glb");
  error_message([&] { write_atlas(plain, dir / "a.glb"); }, dir / "a.glb");
  EXPECT_EQ(read_bytes(dir / "a.glb"), before);
  EXPECT_EQ(list_dir(dir), std::vector<std::string>{"a.glb"});
}

}  // namespace
}  // namespace segmesh
