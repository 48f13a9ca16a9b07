// STL: binary writer, binary/ASCII reader, welding, lying files.
#include <gtest/gtest.h>

#include <cstring>
#include <set>

#include "mesh_test_support.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;

uint32_t u32_at(const std::string& b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}
float f32_at(const std::string& b, size_t at) {
  float v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

// Triangles as corner-position triples, rotated so the smallest corner comes first (winding kept).
std::multiset<std::array<float, 9>> triangle_set(const TriMesh& m) {
  std::multiset<std::array<float, 9>> out;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    std::array<Vec3f, 3> c{m.positions[m.indices[t]], m.positions[m.indices[t + 1]], m.positions[m.indices[t + 2]]};
    const auto less = [](Vec3f a, Vec3f b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); };
    while (less(c[1], c[0]) || less(c[2], c[0])) std::rotate(c.begin(), c.begin() + 1, c.end());
    out.insert({c[0].x, c[0].y, c[0].z, c[1].x, c[1].y, c[1].z, c[2].x, c[2].y, c[2].z});
  }
  return out;
}

TEST(StlTest, BinaryRoundTripWeldsIntoTheClosedCube) {
  const fs::path dir = scratch_dir("stl_round_trip");
  Scene scene;
  scene.parts.push_back(make_part("cube", 1, Role::bone, unit_cube()));
  write_scene(scene, dir / "cube.stl", MeshFormat::stl);
  const Scene back = read_mesh(dir / "cube.stl");
  ASSERT_EQ(back.parts.size(), 1u);
  const TriMesh& m = back.parts[0].mesh;
  EXPECT_EQ(back.parts[0].name, "cube");  // from the "segmesh <name> SPACE=LPS mm" header
  EXPECT_EQ(m.vertex_count(), 8u);        // welded: one vertex per corner
  EXPECT_EQ(m.triangle_count(), 12u);
  EXPECT_TRUE(m.normals.empty());
  EXPECT_TRUE(closed_and_oriented(m));
  for (const auto& [edge, uses] : edge_uses(m)) EXPECT_EQ(uses, 2);
  EXPECT_EQ(triangle_set(m), triangle_set(scene.parts[0].mesh));
  EXPECT_DOUBLE_EQ(signed_volume(m), 1.0);
}

TEST(StlTest, HeaderCountAndFaceNormals) {
  const fs::path dir = scratch_dir("stl_layout");
  write_scene(two_part_scene(), dir / "scene.stl", MeshFormat::stl);
  const std::string b = read_bytes(dir / "scene.stl");
  ASSERT_EQ(b.size(), 84u + 50u * 16u);
  EXPECT_EQ(b.substr(0, 27), "segmesh scene SPACE=LPS mm ");
  EXPECT_EQ(u32_at(b, 80), 16u);  // both parts' triangles in one file
  const Scene scene = two_part_scene();
  for (size_t t = 0; t < 16; ++t) {
    const size_t at = 84 + 50 * t;
    const Vec3f n{f32_at(b, at), f32_at(b, at + 4), f32_at(b, at + 8)};
    const Vec3f a{f32_at(b, at + 12), f32_at(b, at + 16), f32_at(b, at + 20)};
    const Vec3f c1{f32_at(b, at + 24), f32_at(b, at + 28), f32_at(b, at + 32)};
    const Vec3f c2{f32_at(b, at + 36), f32_at(b, at + 40), f32_at(b, at + 44)};
    const Vec3d expect = cross(to_double(c1) - to_double(a), to_double(c2) - to_double(a));
    EXPECT_NEAR(norm(to_double(n)), 1.0, 1e-6);
    EXPECT_NEAR(dot(to_double(n), (1.0 / norm(expect)) * expect), 1.0, 1e-6);
    EXPECT_EQ(b[at + 48], 0);
    EXPECT_EQ(b[at + 49], 0);
  }
}

TEST(StlTest, MovedPartIsWrittenWhereItWasMoved) {
  const fs::path dir = scratch_dir("stl_moved");
  Scene scene;
  scene.parts.push_back(make_part("cube", 1, Role::bone, unit_cube()));
  // A rotation by 90 degrees about z and a translation by (10, 20, 30).
  scene.parts[0].transform = {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 10, 20, 30, 1};
  write_scene(scene, dir / "moved.stl", MeshFormat::stl);
  const TriMesh m = read_mesh(dir / "moved.stl").parts[0].mesh;
  std::set<std::array<float, 3>> corners;
  for (const Vec3f& p : m.positions) corners.insert({p.x, p.y, p.z});
  EXPECT_EQ(corners.count({10, 20, 30}), 1u);
  EXPECT_EQ(corners.count({9, 21, 31}), 1u);  // (1, 1, 1) -> (-1, 1, 1) + t
  EXPECT_TRUE(closed_and_oriented(m));
  EXPECT_NEAR(signed_volume(m), 1.0, 1e-5);
}

TEST(StlTest, AsciiSolidsBecomePartsAndWeld) {
  const fs::path dir = scratch_dir("stl_ascii");
  std::string text;
  const TriMesh tet = tetrahedron();
  for (const char* name : {"first solid", "second"}) {
    text += std::string("solid ") + name + "\n";
    for (size_t t = 0; t < tet.indices.size(); t += 3) {
      text += "  facet normal 0 0 0\n    outer loop\n";
      for (int c = 0; c < 3; ++c) {
        const Vec3f p = tet.positions[tet.indices[t + c]];
        text += "      vertex " + std::to_string(p.x) + " " + std::to_string(p.y) + " +" + std::to_string(p.z) + "\n";
      }
      text += "    endloop\n  endfacet\n";
    }
    text += std::string("endsolid ") + name + "\n";
  }
  write_bytes(dir / "ascii.stl", text);
  const Scene s = read_mesh(dir / "ascii.stl");
  ASSERT_EQ(s.parts.size(), 2u);
  EXPECT_EQ(s.parts[0].name, "first solid");
  EXPECT_EQ(s.parts[1].name, "second");
  for (const Part& p : s.parts) {
    EXPECT_EQ(p.mesh.vertex_count(), 4u);
    EXPECT_TRUE(closed_and_oriented(p.mesh));
  }
  // A binary file whose header happens to start with "solid" is still binary.
  write_scene(two_part_scene(), dir / "bin.stl", MeshFormat::stl);
  std::string b = read_bytes(dir / "bin.stl");
  b.replace(0, 5, "solid");
  write_bytes(dir / "bin_solid.stl", b);
  EXPECT_EQ(read_mesh(dir / "bin_solid.stl").parts.at(0).mesh.triangle_count(), 16u);
}

TEST(StlTest, TruncatedOrLyingFilesAreErrors) {
  const fs::path dir = scratch_dir("stl_lying");
  write_scene(two_part_scene(), dir / "good.stl", MeshFormat::stl);
  const std::string good = read_bytes(dir / "good.stl");

  write_bytes(dir / "truncated.stl", good.substr(0, good.size() - 7));
  std::string msg = error_message([&] { read_mesh(dir / "truncated.stl"); }, dir / "truncated.stl");
  EXPECT_NE(msg.find("truncated"), std::string::npos) << msg;

  std::string lying = good;
  const uint32_t huge = 0xFFFFFFF0u;
  std::memcpy(lying.data() + 80, &huge, 4);
  write_bytes(dir / "lying.stl", lying);
  msg = error_message([&] { read_mesh(dir / "lying.stl"); }, dir / "lying.stl");
  EXPECT_NE(msg.find("4294967280 triangles"), std::string::npos) << msg;

  write_bytes(dir / "short.stl", good.substr(0, 50));
  error_message([&] { read_mesh(dir / "short.stl"); }, dir / "short.stl");

  const std::string ascii =
      "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n";
  write_bytes(dir / "ascii_truncated.stl", ascii);  // no endsolid
  msg = error_message([&] { read_mesh(dir / "ascii_truncated.stl"); }, dir / "ascii_truncated.stl");
  EXPECT_NE(msg.find("line 9"), std::string::npos) << msg;
  write_bytes(dir / "ascii_bad_number.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 zero 0\n");
  msg = error_message([&] { read_mesh(dir / "ascii_bad_number.stl"); }, dir / "ascii_bad_number.stl");
  EXPECT_NE(msg.find("line 4"), std::string::npos) << msg;
}

}  // namespace
}  // namespace segmesh
