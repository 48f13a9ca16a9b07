// Small scenes for the viewer's logic tests: closed boxes whose geometry is known exactly.
#pragma once

#include <cstdint>
#include <string>

#include "segmesh/scene.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh::viewer::test {

// A closed axis-aligned box [lo, hi], 8 vertices, 12 triangles wound counter-clockwise from outside.
inline TriMesh box_mesh(Vec3d lo, Vec3d hi) {
  TriMesh m;
  for (int k = 0; k < 8; ++k) {
    m.positions.push_back(to_float({k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z}));
  }
  // Faces as quads (a, b, c, d) counter-clockwise seen from outside.
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  }
  return m;
}

inline Part box_part(std::string name, int32_t label, int component, Role role, Vec3d lo, Vec3d hi) {
  Part p;
  p.name = std::move(name);
  p.label = label;
  p.component = component;
  p.role = role;
  p.material = default_material(role, label, std::nullopt);
  p.mesh = box_mesh(lo, hi);
  return p;
}

// bone_1 (label 1), bone_2 (label 1), implant_1 (label 2): three boxes side by side.
inline Scene three_boxes() {
  Scene s;
  s.parts.push_back(box_part("bone_1", 1, 1, Role::bone, {0, 0, 0}, {10, 10, 40}));
  s.parts.push_back(box_part("bone_2", 1, 2, Role::bone, {20, 0, 0}, {26, 6, 30}));
  s.parts.push_back(box_part("implant_1", 2, 1, Role::implant, {10, 2, 10}, {12, 8, 30}));
  return s;
}

}  // namespace segmesh::viewer::test
