// The mesh writers stream large meshes in pieces formatted in parallel (mesh_io::write_pieces):
// files must not depend on the thread count, must read back exactly, and a moved part must be
// written exactly as if its mesh had been transformed first.
#include <tbb/global_control.h>

#include <cmath>

#include "mesh_test_support.hpp"
#include "segmesh_io/read_mesh.hpp"
#include "segmesh_io/write_mesh.hpp"
#include "support/test_support.hpp"

namespace segmesh {
namespace {

namespace fs = std::filesystem;
using test::make_part;
using test::read_bytes;
using test::same;

// A closed UV sphere with `rings` x `segments` quads (poles as fans), unit normals and awkward
// coordinates: about rings * segments vertices, enough for many pieces of every format.
TriMesh sphere(int rings, int segments, Vec3f centre, float radius) {
  TriMesh m;
  const double pi = 3.14159265358979323846;
  m.positions.push_back({centre.x, centre.y, centre.z + radius});
  m.normals.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r) {
    const double theta = pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * pi * s / segments;
      const Vec3d n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
      m.positions.push_back(to_float(to_double(centre) + double(radius) * n));
      m.normals.push_back(to_float(n));
    }
  }
  m.positions.push_back({centre.x, centre.y, centre.z - radius});
  m.normals.push_back({0, 0, -1});
  const auto ring = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + (s % segments)); };
  const uint32_t south = uint32_t(m.positions.size() - 1);
  for (int s = 0; s < segments; ++s) m.indices.insert(m.indices.end(), {0, ring(1, s), ring(1, s + 1)});
  for (int r = 1; r + 1 < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      m.indices.insert(m.indices.end(), {ring(r, s), ring(r + 1, s), ring(r + 1, s + 1)});
      m.indices.insert(m.indices.end(), {ring(r, s), ring(r + 1, s + 1), ring(r, s + 1)});
    }
  }
  for (int s = 0; s < segments; ++s) {
    m.indices.insert(m.indices.end(), {south, ring(rings - 1, s + 1), ring(rings - 1, s)});
  }
  return m;
}

// What the writers used to do for a moved part: transform a copy of the mesh.
TriMesh placed(const Part& part) {
  TriMesh m = part.mesh;
  const Transform& t = part.transform;
  for (Vec3f& p : m.positions) {
    const Vec3d q = to_double(p);
    p = to_float(Vec3d{t[0] * q.x + t[4] * q.y + t[8] * q.z + t[12],
                       t[1] * q.x + t[5] * q.y + t[9] * q.z + t[13],
                       t[2] * q.x + t[6] * q.y + t[10] * q.z + t[14]});
  }
  const Vec3d c0{t[0], t[1], t[2]}, c1{t[4], t[5], t[6]}, c2{t[8], t[9], t[10]};
  const Vec3d r0 = cross(c1, c2), r1 = cross(c2, c0), r2 = cross(c0, c1);
  const double det = dot(c0, r0);
  for (Vec3f& n : m.normals) {
    const Vec3d d = to_double(n);
    Vec3d out = (det < 0 ? -1.0 : 1.0) * (d.x * r0 + d.y * r1 + d.z * r2);
    const double len = norm(out);
    n = to_float(len > 0 ? (1.0 / len) * out : out);
  }
  if (det < 0) {
    for (size_t i = 0; i + 2 < m.indices.size(); i += 3) std::swap(m.indices[i + 1], m.indices[i + 2]);
  }
  return m;
}

Scene big_scene() {
  Scene scene;
  scene.parts.push_back(make_part("femur", 1, Role::bone, sphere(400, 500, {-12.3f, 45.6f, -789.1f}, 31.7f)));
  scene.parts.push_back(make_part("screw", 2, Role::implant, sphere(90, 120, {3.3f, 1.1f, -700.7f}, 4.2f)));
  scene.parts.push_back(make_part("plate", 2, Role::implant, sphere(60, 70, {0.1f, 0.2f, 0.3f}, 2.5f)));
  // Some zero normals in a piece far from the first: GLB replaces them by face normals.
  for (size_t v = 30000; v < 30010; ++v) scene.parts[0].mesh.normals[v] = {0, 0, 0};
  // The plate moved by a mirroring transform (rotation about z by 30 degrees, x mirrored).
  const double c = std::cos(0.5235987755982988), s = std::sin(0.5235987755982988);
  scene.parts[2].transform = {-c, -s, 0, 0, -s, c, 0, 0, 0, 0, 1, 0, 10.5, -20.25, 3, 1};
  return scene;
}

const MeshFormat kFormats[] = {MeshFormat::stl, MeshFormat::ply, MeshFormat::obj, MeshFormat::glb};

TEST(MeshWriteStreaming, FilesDoNotDependOnTheThreadCount) {
  const fs::path dir = test::scratch_dir("mesh_write_threads");
  const Scene scene = big_scene();
  fs::create_directories(dir / "one");
  fs::create_directories(dir / "all");
  for (MeshFormat format : kFormats) {
    const std::string name = "scene." + std::string(extension(format));
    {
      tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
      write_scene(scene, dir / "one" / name, format);
    }
    write_scene(scene, dir / "all" / name, format);
    EXPECT_TRUE(read_bytes(dir / "one" / name) == read_bytes(dir / "all" / name)) << name;
  }
  EXPECT_FALSE(test::has_temp_files(dir / "one"));
  EXPECT_FALSE(test::has_temp_files(dir / "all"));
}

TEST(MeshWriteStreaming, LargeMeshesReadBackExactly) {
  const fs::path dir = test::scratch_dir("mesh_write_round_trip");
  Scene scene = big_scene();
  scene.parts[2].transform = identity_transform();  // compared in the next test
  for (MeshFormat format : {MeshFormat::ply, MeshFormat::obj, MeshFormat::glb}) {
    const std::string ext(extension(format));
    write_scene(scene, dir / ("scene." + ext), format);
    const Scene back = read_mesh(dir / ("scene." + ext));
    ASSERT_EQ(back.parts.size(), scene.parts.size()) << ext;
    for (size_t p = 0; p < scene.parts.size(); ++p) {
      const TriMesh& a = scene.parts[p].mesh;
      const TriMesh& b = back.parts[p].mesh;
      ASSERT_EQ(b.positions.size(), a.positions.size()) << ext;
      EXPECT_EQ(b.indices, a.indices) << ext;
      size_t differing = 0;
      for (size_t v = 0; v < a.positions.size(); ++v) differing += !same(a.positions[v], b.positions[v]);
      EXPECT_EQ(differing, 0u) << ext << " part " << p;
      ASSERT_EQ(b.normals.size(), a.normals.size()) << ext;
      if (format == MeshFormat::glb) {
        for (size_t v = 0; v < b.normals.size(); ++v) {
          ASSERT_NEAR(norm(to_double(b.normals[v])), 1.0, 1e-6) << "part " << p << " vertex " << v;
        }
      } else {
        differing = 0;
        for (size_t v = 0; v < a.normals.size(); ++v) differing += !same(a.normals[v], b.normals[v]);
        EXPECT_EQ(differing, 0u) << ext << " part " << p;
      }
    }
  }
  const fs::path stl = dir / "scene.stl";
  write_scene(scene, stl, MeshFormat::stl);
  size_t triangles = 0;
  for (const Part& part : scene.parts) triangles += part.mesh.triangle_count();
  EXPECT_EQ(fs::file_size(stl), 84 + 50 * triangles);
  size_t back_triangles = 0;
  for (const Part& part : read_mesh(stl).parts) back_triangles += part.mesh.triangle_count();
  EXPECT_EQ(back_triangles, triangles);
}

TEST(MeshWriteStreaming, AMovedPartIsWrittenAsItsTransformedMesh) {
  const fs::path dir = test::scratch_dir("mesh_write_moved");
  const Scene moved = big_scene();
  Scene baked = moved;
  baked.parts[2].mesh = placed(moved.parts[2]);
  baked.parts[2].transform = identity_transform();
  fs::create_directories(dir / "moved");
  fs::create_directories(dir / "baked");
  for (MeshFormat format : {MeshFormat::stl, MeshFormat::ply, MeshFormat::obj}) {
    const std::string name = "scene." + std::string(extension(format));
    write_scene(moved, dir / "moved" / name, format);
    write_scene(baked, dir / "baked" / name, format);
    EXPECT_TRUE(read_bytes(dir / "moved" / name) == read_bytes(dir / "baked" / name)) << name;
  }
}

}  // namespace
}  // namespace segmesh
