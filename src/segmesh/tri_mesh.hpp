// TriMesh: an indexed triangle mesh as flat arrays.
//
// positions and (optional) normals/colors hold one entry per vertex; indices three per triangle,
// counter-clockwise seen from outside, so a closed mesh encloses a positive volume. Coordinates
// are world millimetres. Vertices are shared between triangles (one per cut edge for Marching
// Cubes), which is what makes closedness and manifoldness checkable.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/vec3.hpp"

namespace segmesh {

using Rgba8 = std::array<uint8_t, 4>;

struct TriMesh {
  std::vector<Vec3f> positions;
  std::vector<Vec3f> normals;    // empty, or one unit normal per vertex
  std::vector<uint32_t> indices;  // 3 per triangle
  std::vector<Rgba8> colors;      // empty, or one colour per vertex

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return indices.size() / 3; }
  bool empty() const { return indices.empty(); }
};

}  // namespace segmesh
