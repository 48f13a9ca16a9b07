// PLY: binary little-endian writer; ASCII / binary LE / binary BE reader; lying files.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>

#include "mesh_test_support.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;

std::string header_of(const std::string& bytes) {
  return bytes.substr(0, bytes.find("end_header\n") + 11);
}

TEST(PlyTest, TwoPartsRoundTripWithNamesMaterialsAndNormals) {
  const fs::path dir = scratch_dir("ply_round_trip");
  Scene scene = two_part_scene();
  scene.parts[1].name = "plate with spaces";
  scene.parts[1].visible = false;
  scene.parts[1].component = 3;
  write_scene(scene, dir / "scene.ply", MeshFormat::ply);
  const Scene back = read_mesh(dir / "scene.ply");
  ASSERT_EQ(back.parts.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const Part& a = scene.parts[i];
    const Part& b = back.parts[i];
    SCOPED_TRACE(a.name);
    expect_same_part_info(b, a);
    EXPECT_EQ(b.mesh.indices, a.mesh.indices);
    ASSERT_EQ(b.mesh.vertex_count(), a.mesh.vertex_count());
    ASSERT_EQ(b.mesh.normals.size(), a.mesh.normals.size());
    for (size_t v = 0; v < a.mesh.vertex_count(); ++v) {
      EXPECT_TRUE(same(b.mesh.positions[v], a.mesh.positions[v]));
      EXPECT_TRUE(same(b.mesh.normals[v], a.mesh.normals[v]));
    }
    // The material colour the writer filled in for viewers is not per-vertex data.
    EXPECT_TRUE(b.mesh.colors.empty());
  }
}

TEST(PlyTest, HeaderDeclaresLayoutUnitsAndParts) {
  const fs::path dir = scratch_dir("ply_header");
  const Scene scene = two_part_scene();
  write_scene(scene, dir / "scene.ply", MeshFormat::ply);
  const std::string bytes = read_bytes(dir / "scene.ply");
  const std::string h = header_of(bytes);
  EXPECT_TRUE(h.starts_with("ply\nformat binary_little_endian 1.0\n")) << h;
  for (const char* line :
       {"comment SPACE=LPS\n", "comment units mm\n", "element vertex 12\n", "property float x\n",
        "property float nx\n", "property uchar red\n", "property uchar alpha\n", "element face 16\n",
        "property list uchar uint vertex_indices\n", " name=tibia\n", " name=plate\n", " role=implant "}) {
    EXPECT_NE(h.find(line), std::string::npos) << line << " missing in\n" << h;
  }
  // Several parts without vertex colours: each vertex carries its part's material colour.
  const size_t vertex_size = 12 + 12 + 4;
  ASSERT_EQ(bytes.size(), h.size() + 12 * vertex_size + 16 * 13);
  const auto rgba = [&](size_t v) { return bytes.substr(h.size() + v * vertex_size + 24, 4); };
  const Rgb bone = scene.parts[0].material.base_color, implant = scene.parts[1].material.base_color;
  EXPECT_EQ(uint8_t(rgba(0)[0]), uint8_t(std::lround(bone.r * 255)));
  EXPECT_EQ(uint8_t(rgba(0)[2]), uint8_t(std::lround(bone.b * 255)));
  EXPECT_EQ(uint8_t(rgba(8)[0]), uint8_t(std::lround(implant.r * 255)));
  EXPECT_EQ(uint8_t(rgba(8)[1]), uint8_t(std::lround(implant.g * 255)));
  EXPECT_EQ(uint8_t(rgba(8)[3]), 255);
  // Face list: count 3 then global uint32 indices (the plate's first vertex is 8).
  const size_t faces = h.size() + 12 * vertex_size;
  EXPECT_EQ(bytes[faces], 3);
  uint32_t first_plate_index;
  std::memcpy(&first_plate_index, bytes.data() + faces + 12 * 13 + 1, 4);
  EXPECT_EQ(first_plate_index, 8u);
}

TEST(PlyTest, VertexColoursRoundTripAndSinglePartHasNoColourWhenItHasNone) {
  const fs::path dir = scratch_dir("ply_colours");
  Scene scene;
  scene.parts.push_back(make_part("cube", 1, Role::bone, unit_cube()));
  write_scene(scene, dir / "plain.ply", MeshFormat::ply);
  EXPECT_EQ(header_of(read_bytes(dir / "plain.ply")).find("red"), std::string::npos);
  EXPECT_TRUE(read_mesh(dir / "plain.ply").parts[0].mesh.colors.empty());

  scene.parts[0].mesh.normals.clear();
  for (size_t v = 0; v < 8; ++v) scene.parts[0].mesh.colors.push_back({uint8_t(v * 30), 7, 200, uint8_t(255 - v)});
  write_scene(scene, dir / "coloured.ply", MeshFormat::ply);
  EXPECT_EQ(header_of(read_bytes(dir / "coloured.ply")).find("nx"), std::string::npos);
  const TriMesh m = read_mesh(dir / "coloured.ply").parts.at(0).mesh;
  EXPECT_EQ(m.colors, scene.parts[0].mesh.colors);
  EXPECT_TRUE(m.normals.empty());
}

TEST(PlyTest, ReadsAsciiPolygonsAndBigEndian) {
  const fs::path dir = scratch_dir("ply_foreign");
  // A cube as six quads in ASCII, with an extra vertex property and an extra element to skip.
  write_bytes(dir / "quads.ply",
              "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nelement vertex 8\r\n"
              "property double x\r\nproperty double y\r\nproperty double z\r\nproperty int flags\r\n"
              "element face 6\r\nproperty list uchar int vertex_index\r\n"
              "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
              "0 0 0 1\r\n1 0 0 1\r\n0 1 0 1\r\n1 1 0 1\r\n0 0 1 1\r\n1 0 1 1\r\n0 1 1 1\r\n1 1 1 1\r\n"
              "4 0 2 3 1\r\n4 4 5 7 6\r\n4 0 1 5 4\r\n4 2 6 7 3\r\n4 0 4 6 2\r\n4 1 3 7 5\r\n0 1\r\n");
  Scene s = read_mesh(dir / "quads.ply");
  ASSERT_EQ(s.parts.size(), 1u);
  EXPECT_EQ(s.parts[0].name, "quads");
  EXPECT_EQ(s.parts[0].mesh.triangle_count(), 12u);
  EXPECT_TRUE(closed_and_oriented(s.parts[0].mesh));
  EXPECT_DOUBLE_EQ(signed_volume(s.parts[0].mesh), 1.0);

  // One triangle, big-endian, with ushort list counts and float colours.
  std::string be = "ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                   "property float z\nproperty float red\nproperty float green\nproperty float blue\n"
                   "element face 1\nproperty list ushort uint vertex_indices\nend_header\n";
  const auto put = [&](auto v) {
    char b[sizeof(v)];
    std::memcpy(b, &v, sizeof(v));
    if constexpr (std::endian::native == std::endian::little) std::reverse(b, b + sizeof(v));
    be.append(b, sizeof(v));
  };
  const float corners[3][3] = {{1.5f, 2, 3}, {4, 5, 6}, {7, 8, -9.25f}};
  for (const auto& c : corners) {
    put(c[0]), put(c[1]), put(c[2]);
    put(1.0f), put(0.5f), put(0.0f);
  }
  put(uint16_t{3}), put(uint32_t{0}), put(uint32_t{1}), put(uint32_t{2});
  write_bytes(dir / "be.ply", be);
  s = read_mesh(dir / "be.ply");
  const TriMesh& m = s.parts.at(0).mesh;
  ASSERT_EQ(m.vertex_count(), 3u);
  EXPECT_TRUE(same(m.positions[2], Vec3f{7, 8, -9.25f}));
  EXPECT_EQ(m.indices, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(m.colors.at(1), (Rgba8{255, 128, 0, 255}));
}

TEST(PlyTest, LyingOrTruncatedFilesAreErrors) {
  const fs::path dir = scratch_dir("ply_lying");
  write_scene(two_part_scene(), dir / "good.ply", MeshFormat::ply);
  const std::string good = read_bytes(dir / "good.ply");
  const auto check = [&](const std::string& name, const std::string& bytes, const char* expect) {
    write_bytes(dir / name, bytes);
    const std::string msg = error_message([&] { read_mesh(dir / name); }, dir / name);
    EXPECT_NE(msg.find(expect), std::string::npos) << msg;
  };
  check("truncated.ply", good.substr(0, good.size() - 5), "truncated");
  check("no_end_header.ply", good.substr(0, header_of(good).size() - 8), "end_header");

  std::string lying = good;
  lying.replace(lying.find("element vertex 12"), 17, "element vertex 4000000000");
  check("lying_vertices.ply", lying, "4000000000");
  lying = good;
  lying.replace(lying.find("element face 16"), 15, "element face 999999999999");
  check("lying_faces.ply", lying, "999999999999");

  // A face that names vertex 12 of 12.
  std::string bad_index = good;
  const uint32_t twelve = 12;
  std::memcpy(bad_index.data() + bad_index.size() - 4, &twelve, 4);
  check("bad_index.ply", bad_index, "vertex 12");

  check("ascii_short.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 0 0\n", "data bytes");
  check("ascii_word.ply", "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n0 0 0\n1 zero 0\n", "zero");
  check("bad_format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n", "binary_middle_endian");
  check("list_huge.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uint uint vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n4000000000 0 1 2\n", "truncated");
}

}  // namespace
}  // namespace segmesh
