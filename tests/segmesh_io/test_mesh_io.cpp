// Mesh writers and readers through the public entry points: format names, write_scene /
// write_parts / read_mesh for every format, atomic output and errors.
#include <gtest/gtest.h>

#include <random>

#include "mesh_test_support.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using namespace segmesh::test;

const MeshFormat kAllFormats[] = {MeshFormat::stl, MeshFormat::ply, MeshFormat::obj, MeshFormat::glb};

TEST(MeshFormatTest, FromPathIsCaseInsensitive) {
  EXPECT_EQ(mesh_format_from_path("a/b/scene.stl"), MeshFormat::stl);
  EXPECT_EQ(mesh_format_from_path("SCENE.PLY"), MeshFormat::ply);
  EXPECT_EQ(mesh_format_from_path("x.Obj"), MeshFormat::obj);
  EXPECT_EQ(mesh_format_from_path("x.y.GLB"), MeshFormat::glb);
  EXPECT_EQ(mesh_format_from_path("x.gltf"), std::nullopt);
  EXPECT_EQ(mesh_format_from_path("stl"), std::nullopt);
  EXPECT_EQ(mesh_format_from_path("noext"), std::nullopt);
}

TEST(MeshFormatTest, ParseAndExtensionAgree) {
  for (MeshFormat f : kAllFormats) {
    EXPECT_EQ(parse_mesh_format(extension(f)), f);
    EXPECT_EQ(mesh_format_from_path("part." + std::string(extension(f))), f);
  }
  EXPECT_EQ(parse_mesh_format("GLB"), MeshFormat::glb);
  EXPECT_EQ(parse_mesh_format(".ply"), MeshFormat::ply);
  EXPECT_EQ(parse_mesh_format("vtk"), std::nullopt);
  EXPECT_EQ(parse_mesh_format(""), std::nullopt);
}

// Every format keeps every part closed and outward-oriented, with its volume.
TEST(MeshRoundTripTest, EveryFormatKeepsClosedOrientedParts) {
  const fs::path dir = scratch_dir("mesh_round_trip_all");
  const Scene scene = two_part_scene();
  const double volume = signed_volume(scene.parts[0].mesh) + signed_volume(scene.parts[1].mesh);
  for (MeshFormat f : kAllFormats) {
    SCOPED_TRACE(std::string(extension(f)));
    const fs::path file = dir / ("scene." + std::string(extension(f)));
    write_scene(scene, file, f);
    const Scene back = read_mesh(file);
    ASSERT_FALSE(back.parts.empty());
    double v = 0;
    size_t triangles = 0;
    for (const Part& p : back.parts) {
      EXPECT_TRUE(closed_and_oriented(p.mesh)) << p.name;
      v += signed_volume(p.mesh);
      triangles += p.mesh.triangle_count();
    }
    EXPECT_EQ(triangles, 16u);
    EXPECT_NEAR(v, volume, 1e-6 * std::abs(volume));
    EXPECT_GT(v, 0);
    EXPECT_EQ(back.parts.size(), f == MeshFormat::stl ? 1u : 2u);
  }
  EXPECT_FALSE(has_temp_files(dir));
}

TEST(MeshWriteTest, WritePartsNamesFilesAfterPartsUniquely) {
  const fs::path dir = scratch_dir("mesh_write_parts") / "parts";  // created by write_parts
  Scene scene;
  scene.parts.push_back(make_part("Left Tibia", 1, Role::bone, unit_cube()));
  scene.parts.push_back(make_part("left tibia", 1, Role::bone, tetrahedron()));
  scene.parts.push_back(make_part("../evil/name", 2, Role::implant, tetrahedron()));
  scene.parts.push_back(make_part("", 3, Role::other, tetrahedron()));
  scene.parts.push_back(make_part("empty", 4, Role::other, TriMesh{}));
  for (MeshFormat f : kAllFormats) {
    SCOPED_TRACE(std::string(extension(f)));
    const std::string ext = "." + std::string(extension(f));
    const std::vector<fs::path> files = write_parts(scene, dir, f);
    ASSERT_EQ(files.size(), 4u);  // the empty part is skipped
    EXPECT_EQ(files[0], dir / ("Left_Tibia" + ext));
    EXPECT_EQ(files[1], dir / ("left_tibia_2" + ext));
    EXPECT_EQ(files[2], dir / ("_evil_name" + ext));
    EXPECT_EQ(files[3], dir / ("part" + ext));
    for (size_t i = 0; i < files.size(); ++i) {
      ASSERT_TRUE(fs::exists(files[i]));
      EXPECT_EQ(files[i].parent_path(), dir);
      const Scene back = read_mesh(files[i]);
      ASSERT_EQ(back.parts.size(), 1u);
      EXPECT_EQ(back.parts[0].mesh.triangle_count(), i == 0 ? 12u : 4u);
      if (f != MeshFormat::stl && !scene.parts[i].name.empty()) {
        EXPECT_EQ(back.parts[0].name, scene.parts[i].name);
      }
      if (f == MeshFormat::obj) {
        fs::path mtl = files[i];
        EXPECT_TRUE(fs::exists(mtl.replace_extension(".mtl")));
      }
    }
    EXPECT_FALSE(has_temp_files(dir));
  }
  EXPECT_EQ(list_dir(dir).size(), 4u * 4u + 4u);  // 4 parts in 4 formats, plus 4 .mtl files
}

TEST(MeshWriteTest, MissingFolderIsAnErrorAndLeavesNothing) {
  const fs::path base = scratch_dir("mesh_missing_folder");
  const Scene scene = two_part_scene();
  for (MeshFormat f : kAllFormats) {
    SCOPED_TRACE(std::string(extension(f)));
    const fs::path file = base / "no_such_folder" / ("scene." + std::string(extension(f)));
    const std::string msg = error_message([&] { write_scene(scene, file, f); }, file);
    EXPECT_NE(msg.find("no_such_folder"), std::string::npos) << msg;
    const fs::path dir = base / "no_such_parent" / "parts";
    error_message([&] { write_parts(scene, dir, f); }, dir);
  }
  EXPECT_TRUE(list_dir(base).empty());
}

// A failure on the second part (its target name is taken by a folder) must leave no file of the
// first part and no temporary file.
TEST(MeshWriteTest, FailedWritePartsLeavesNothing) {
  for (MeshFormat f : kAllFormats) {
    SCOPED_TRACE(std::string(extension(f)));
    const fs::path dir = scratch_dir("mesh_write_parts_fail");
    fs::create_directory(dir / ("plate." + std::string(extension(f))));
    const fs::path target = dir / ("plate." + std::string(extension(f)));
    error_message([&] { write_parts(two_part_scene(), dir, f); }, target);
    EXPECT_EQ(list_dir(dir), std::vector<std::string>{"plate." + std::string(extension(f))});
  }
  // A folder that write_parts created is removed again.
  const fs::path base = scratch_dir("mesh_write_parts_fail_created");
  Scene bad = two_part_scene();
  bad.parts[1].mesh.indices[0] = 99;  // malformed mesh: a programming fault, caught before writing
  EXPECT_THROW(write_parts(bad, base / "new", MeshFormat::stl), std::invalid_argument);
  EXPECT_TRUE(list_dir(base).empty());
}

TEST(MeshWriteTest, SuccessLeavesNoTemporaryFilesAndReplacesOldFiles) {
  const fs::path dir = scratch_dir("mesh_no_temp");
  for (MeshFormat f : kAllFormats) {
    const fs::path file = dir / ("scene." + std::string(extension(f)));
    write_bytes(file, "old content");
    write_scene(two_part_scene(), file, f);
    EXPECT_NE(read_bytes(file), "old content");
    write_parts(two_part_scene(), dir / "parts", f);
  }
  EXPECT_FALSE(has_temp_files(dir));
  EXPECT_FALSE(has_temp_files(dir / "parts"));
  EXPECT_EQ(list_dir(dir), (std::vector<std::string>{"parts", "scene.glb", "scene.mtl", "scene.obj",
                                                     "scene.ply", "scene.stl"}));
}

TEST(MeshWriteTest, EmptySceneWritesValidEmptyFiles) {
  const fs::path dir = scratch_dir("mesh_empty_scene");
  Scene scene;
  scene.parts.push_back(make_part("nothing", 1, Role::bone, TriMesh{}));
  for (MeshFormat f : kAllFormats) {
    const fs::path file = dir / ("empty." + std::string(extension(f)));
    write_scene(scene, file, f);
    const Scene back = read_mesh(file);
    size_t triangles = 0;
    for (const Part& p : back.parts) triangles += p.mesh.triangle_count();
    EXPECT_EQ(triangles, 0u) << file;
  }
  EXPECT_TRUE(write_parts(scene, dir / "parts", MeshFormat::stl).empty());
}

TEST(MeshReadTest, MissingUnknownAndEmptyFilesAreErrors) {
  const fs::path dir = scratch_dir("mesh_read_errors");
  error_message([&] { read_mesh(dir / "missing.stl"); }, dir / "missing.stl");
  write_bytes(dir / "notes.txt", "hello, this is not a mesh\n");
  const std::string msg = error_message([&] { read_mesh(dir / "notes.txt"); }, dir / "notes.txt");
  EXPECT_NE(msg.find("unknown mesh format"), std::string::npos) << msg;
  for (MeshFormat f : kAllFormats) {
    const fs::path file = dir / ("zero." + std::string(extension(f)));
    write_bytes(file, "");
    if (f == MeshFormat::obj) {
      EXPECT_TRUE(read_mesh(file).parts.empty());  // an empty OBJ is a valid empty scene
    } else {
      error_message([&] { read_mesh(file); }, file);
    }
  }
  error_message([&] { read_mesh(dir); }, dir);
}

// The content decides over a misleading extension.
TEST(MeshReadTest, ContentBeatsExtension) {
  const fs::path dir = scratch_dir("mesh_read_sniff");
  write_scene(two_part_scene(), dir / "scene.glb", MeshFormat::glb);
  fs::copy_file(dir / "scene.glb", dir / "really_glb.stl");
  EXPECT_EQ(read_mesh(dir / "really_glb.stl").parts.size(), 2u);
  write_scene(two_part_scene(), dir / "scene.ply", MeshFormat::ply);
  fs::copy_file(dir / "scene.ply", dir / "really_ply.bin");
  EXPECT_EQ(read_mesh(dir / "really_ply.bin").parts.size(), 2u);
  write_scene(two_part_scene(), dir / "scene.stl", MeshFormat::stl);
  fs::copy_file(dir / "scene.stl", dir / "really_stl.dat");
  EXPECT_EQ(read_mesh(dir / "really_stl.dat").parts[0].mesh.triangle_count(), 16u);
}

// Random byte flips and truncations of valid files: each read either succeeds or throws
// segmesh::Error; never a crash, another exception or a huge allocation (run under ASan/UBSan).
TEST(MeshReadTest, CorruptedFilesGiveErrorsNotCrashes) {
  const fs::path dir = scratch_dir("mesh_corrupt");
  std::mt19937 rng(12345);
  Scene scene = two_part_scene();
  scene.parts[0].mesh.colors.assign(8, Rgba8{1, 2, 3, 4});
  for (MeshFormat f : kAllFormats) {
    SCOPED_TRACE(std::string(extension(f)));
    const fs::path good = dir / ("good." + std::string(extension(f)));
    write_scene(scene, good, f);
    const std::string bytes = read_bytes(good);
    const fs::path bad = dir / ("bad." + std::string(extension(f)));
    if (f == MeshFormat::obj) fs::copy_file(dir / "good.mtl", dir / "bad.mtl");
    int errors = 0;
    for (int round = 0; round < 400; ++round) {
      std::string b = bytes;
      if (round % 4 == 3) {
        b.resize(std::uniform_int_distribution<size_t>(0, b.size() - 1)(rng));
      } else {
        const int flips = 1 + round % 4;
        for (int k = 0; k < flips; ++k) {
          const size_t at = std::uniform_int_distribution<size_t>(0, b.size() - 1)(rng);
          b[at] = static_cast<char>(std::uniform_int_distribution<int>(0, 255)(rng));
        }
      }
      write_bytes(bad, b);
      try {
        const Scene s = read_mesh(bad);
        for (const Part& p : s.parts) {
          for (uint32_t i : p.mesh.indices) ASSERT_LT(i, p.mesh.vertex_count());
        }
      } catch (const Error&) {
        ++errors;
      } catch (const std::exception& e) {
        ADD_FAILURE() << "round " << round << ": not a segmesh::Error: " << e.what();
      }
    }
    EXPECT_GT(errors, 0);
  }
}

}  // namespace
}  // namespace segmesh
