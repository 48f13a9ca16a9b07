// OBJ + MTL: writer layout, round trip, foreign files, bad indices.
#include <gtest/gtest.h>

#include "mesh_test_support.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;

TEST(ObjTest, WritesObjectsMaterialsAndPbrKeys) {
  const fs::path dir = scratch_dir("obj_layout");
  Scene scene = two_part_scene();
  scene.parts[0].mesh.normals.clear();
  write_scene(scene, dir / "scene.obj", MeshFormat::obj);
  const std::string obj = read_bytes(dir / "scene.obj");
  const std::string mtl = read_bytes(dir / "scene.mtl");
  for (const char* text : {"mtllib scene.mtl\n", "\no tibia\nusemtl tibia\n", "\no plate\nusemtl plate\n",
                           "\nf 1 3 2\n", "\nf 9//1 11//3 10//2\n", "role=implant"}) {
    EXPECT_NE(obj.find(text), std::string::npos) << text;
  }
  // The cube has no normals, so the plate's normals are numbered from 1.
  EXPECT_EQ(obj.find("\nvn ", obj.find("o tibia")), obj.find("\nvn ", obj.find("o plate")));
  for (const char* text : {"newmtl tibia\n", "Kd 0.95 0.93 0.88\n", "Pr 0.6\n", "Pm 0\n",
                           "newmtl plate\n", "Kd 0.8 0.05 0.05\n", "Pr 0.7\n", "Pm 1\n"}) {
    EXPECT_NE(mtl.find(text), std::string::npos) << text << " missing in\n" << mtl;
  }
}

TEST(ObjTest, RoundTripKeepsNamesMaterialsPositionsIndicesNormals) {
  const fs::path dir = scratch_dir("obj_round_trip");
  Scene scene = two_part_scene();
  scene.parts[1].name = "plate 2";  // a space: the material name becomes plate_2
  scene.parts.push_back(make_part("plate 2", 3, Role::other, tetrahedron()));  // same name again
  write_scene(scene, dir / "scene.obj", MeshFormat::obj);
  const Scene back = read_mesh(dir / "scene.obj");
  ASSERT_EQ(back.parts.size(), 3u);
  EXPECT_NE(read_bytes(dir / "scene.mtl").find("newmtl plate_2_2\n"), std::string::npos);
  for (size_t i = 0; i < 3; ++i) {
    const Part& a = scene.parts[i];
    const Part& b = back.parts[i];
    SCOPED_TRACE(a.name);
    expect_same_part_info(b, a);
    EXPECT_EQ(b.mesh.indices, a.mesh.indices);
    ASSERT_EQ(b.mesh.vertex_count(), a.mesh.vertex_count());
    ASSERT_EQ(b.mesh.normals.size(), a.mesh.normals.size());
    for (size_t v = 0; v < a.mesh.vertex_count(); ++v) {
      EXPECT_TRUE(same(b.mesh.positions[v], a.mesh.positions[v]));  // shortest exact decimal
      if (!a.mesh.normals.empty()) {
        EXPECT_TRUE(same(b.mesh.normals[v], a.mesh.normals[v]));
      }
    }
  }
}

TEST(ObjTest, ReadsForeignFilesWithGroupsPolygonsAndRelativeIndices) {
  const fs::path dir = scratch_dir("obj_foreign");
  write_bytes(dir / "shapes.mtl", "newmtl Red Metal\nKd 1 0 0\nPm 0.9\nPr 0.2\n");
  write_bytes(dir / "shapes.obj",
              "# by hand\nmtllib shapes.mtl\n"
              "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
              "vt 0 0\n"
              "g cube\nusemtl Red Metal\ns off\n"
              "f 1/1 3/1 4/1 2/1\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n"
              "g tet\n"
              "v 0 0 0 1 0 0\nv 1 0 0 1 0 0\nv 0 1 0 1 0 0\nv 0 0 1 1 0 0\n"
              "f -4 -2 -3\nf -4 -3 -1\nf -4 -1 -2\nf -3 -2 -1\n");
  const Scene s = read_mesh(dir / "shapes.obj");
  ASSERT_EQ(s.parts.size(), 2u);
  EXPECT_EQ(s.parts[0].name, "cube");
  EXPECT_EQ(s.parts[0].mesh.triangle_count(), 12u);
  EXPECT_TRUE(closed_and_oriented(s.parts[0].mesh));
  EXPECT_DOUBLE_EQ(signed_volume(s.parts[0].mesh), 1.0);
  EXPECT_EQ(s.parts[0].material.base_color.r, 1.0f);
  EXPECT_EQ(s.parts[0].material.metallic, 0.9f);
  EXPECT_EQ(s.parts[0].material.roughness, 0.2f);
  EXPECT_TRUE(s.parts[0].mesh.colors.empty());
  EXPECT_EQ(s.parts[1].name, "tet");
  EXPECT_EQ(s.parts[1].mesh.vertex_count(), 4u);
  EXPECT_TRUE(closed_and_oriented(s.parts[1].mesh));
  EXPECT_EQ(s.parts[1].mesh.colors.at(0), (Rgba8{255, 0, 0, 255}));

  // No o or g: one part named after the file; a missing MTL leaves the default material.
  write_bytes(dir / "plain.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n");
  const Scene p = read_mesh(dir / "plain.obj");
  ASSERT_EQ(p.parts.size(), 1u);
  EXPECT_EQ(p.parts[0].name, "plain");
}

TEST(ObjTest, BadIndicesAndNumbersAreErrors) {
  const fs::path dir = scratch_dir("obj_bad");
  const auto check = [&](const std::string& name, const std::string& text, const char* expect) {
    write_bytes(dir / name, text);
    const std::string msg = error_message([&] { read_mesh(dir / name); }, dir / name);
    EXPECT_NE(msg.find(expect), std::string::npos) << msg;
  };
  check("out_of_range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "line 4: vertex index 4 is out of range");
  check("negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", "out of range");
  check("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "bad vertex index");
  check("normal.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n", "normal index 2");
  check("two_corners.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n", "at least 3 corners");
  check("bad_number.obj", "v 0 0 0\nv 1 zero 0\n", "line 2: bad number");
  check("huge_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999999\n", "bad vertex index");
}

}  // namespace
}  // namespace segmesh
