// Small hand-built meshes and checks shared by the mesh I/O tests.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "segmesh/error.hpp"
#include "segmesh/image.hpp"
#include "segmesh/scene.hpp"

namespace segmesh::test {

// Unit tetrahedron at the origin, counter-clockwise seen from outside.
inline TriMesh tetrahedron() {
  TriMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  m.indices = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  return m;
}

// Unit cube [0,1]^3 with 8 shared vertices (index x + 2y + 4z) and 12 outward triangles, with
// unit corner normals.
inline TriMesh unit_cube() {
  TriMesh m;
  for (int i = 0; i < 8; ++i) {
    const float x = float(i & 1), y = float((i >> 1) & 1), z = float((i >> 2) & 1);
    m.positions.push_back({x, y, z});
    const float s = 0.57735026918962576f;
    m.normals.push_back({(x * 2 - 1) * s, (y * 2 - 1) * s, (z * 2 - 1) * s});
  }
  m.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 5, 0, 5, 4,
               2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
  return m;
}

inline Part make_part(std::string name, int32_t label, Role role, TriMesh mesh) {
  Part p;
  p.name = std::move(name);
  p.label = label;
  p.role = role;
  p.material = default_material(role, label, std::nullopt);
  p.mesh = std::move(mesh);
  p.voxels = 1000 + label;
  p.voxel_volume_mm3 = 0.5 * p.voxels;
  return p;
}

// What a segmesh file keeps of a part besides its mesh: the part `b` read back has `a`'s name,
// label, component, role, voxels, visibility and material.
inline void expect_same_part_info(const Part& b, const Part& a) {
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.label, a.label);
  EXPECT_EQ(b.component, a.component);
  EXPECT_EQ(b.role, a.role);
  EXPECT_EQ(b.voxels, a.voxels);
  EXPECT_EQ(b.visible, a.visible);
  EXPECT_EQ(b.material.base_color.r, a.material.base_color.r);
  EXPECT_EQ(b.material.base_color.g, a.material.base_color.g);
  EXPECT_EQ(b.material.base_color.b, a.material.base_color.b);
  EXPECT_EQ(b.material.metallic, a.material.metallic);
  EXPECT_EQ(b.material.roughness, a.material.roughness);
}

// A bone cube and an implant tetrahedron moved away from it (in the coordinates, not the
// transform), positions with awkward float values.
inline Scene two_part_scene() {
  Scene s;
  TriMesh cube = unit_cube();
  for (Vec3f& p : cube.positions) p = {p.x * 10.1f - 3.3f, p.y * 20.7f + 0.1f, p.z * 5.3f - 100.25f};
  TriMesh tet = tetrahedron();
  for (Vec3f& p : tet.positions) p = {p.x * 4 + 30.5f, p.y * 3 + 1.0f / 3.0f, p.z * 2 - 7};
  tet.normals.assign(tet.positions.size(), Vec3f{0, 0, 1});
  s.parts.push_back(make_part("tibia", 1, Role::bone, cube));
  s.parts.push_back(make_part("plate", 2, Role::implant, tet));
  return s;
}

// Number of uses of each undirected edge.
inline std::map<std::pair<uint32_t, uint32_t>, int> edge_uses(const TriMesh& m) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      uint32_t a = m.indices[t + e], b = m.indices[t + (e + 1) % 3];
      if (a > b) std::swap(a, b);
      ++uses[{a, b}];
    }
  }
  return uses;
}

// Closed and consistently oriented: every undirected edge used exactly twice, every directed edge
// exactly once.
inline bool closed_and_oriented(const TriMesh& m) {
  for (const auto& [edge, n] : edge_uses(m)) {
    if (n != 2) return false;
  }
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      if (++directed[{m.indices[t + e], m.indices[t + (e + 1) % 3]}] != 1) return false;
    }
  }
  return !m.indices.empty();
}

inline double signed_volume(const TriMesh& m) {
  double v = 0;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const Vec3d a = to_double(m.positions[m.indices[t]]), b = to_double(m.positions[m.indices[t + 1]]),
                c = to_double(m.positions[m.indices[t + 2]]);
    v += dot(a, cross(b, c)) / 6.0;
  }
  return v;
}

inline std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::filesystem::path& file, const std::string& bytes) {
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// Names of the entries in `dir`, sorted.
inline std::vector<std::string> list_dir(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

inline bool has_temp_files(const std::filesystem::path& dir) {
  for (const std::string& n : list_dir(dir)) {
    if (n.find(".tmp-") != std::string::npos) return true;
  }
  return false;
}

inline bool same(Vec3f a, Vec3f b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

// The message of the segmesh::Error `fn` throws; a test failure when it throws nothing (or
// something else). Checks that the message is one line naming `file`.
template <class Fn>
std::string error_message(Fn fn, const std::filesystem::path& file) {
  try {
    fn();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(file.filename().string()), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    return msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected segmesh::Error, got: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected segmesh::Error for " << file;
  return {};
}

// Boxes on an anisotropic grid away from the origin: a block (label 1) and a second block beside
// it (label 2, its name with a space) and, when `touching`, a cap (label 3) lying across the two,
// so that parts touch each other and the background along junction curves. Otherwise the blocks
// stand two voxels apart and there is no cap: no part touches another.
inline Image touching_boxes(bool touching) {
  Volume<uint8_t> v;
  v.grid.dims = {24, 20, 16};
  v.grid.spacing = {0.5, 0.6, 0.7};
  v.grid.origin = {-10.25, 5.5, 2.0};
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 3; k < 13; ++k)
    for (int64_t j = 3; j < 17; ++j)
      for (int64_t i = 3; i < 21; ++i) {
        if (k < 9 && (touching || i < 10 || i >= 12)) v.at(i, j, k) = i < 12 ? 1 : 2;
        if (k >= 9 && touching && i >= 8 && i < 16 && j >= 6 && j < 14) v.at(i, j, k) = 3;
      }
  return Image{.path = "boxes", .voxel_type = "uint8", .volume = std::move(v)};
}

}  // namespace segmesh::test
