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
#include <limits>
#include <string>
#include <vector>

#include "segmesh/error.hpp"
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

// Vertex ids are 32-bit, and so are the extractors' counts and first ids per row of the grid (half
// the bytes of 64-bit ones, whose pages each part touches afresh). `n`, a count added up in 64
// bits, as such an id; throws segmesh::Error, naming the extractor `who`, past what 32 bits hold.
[[noreturn, gnu::cold, gnu::noinline]] inline void throw_too_many_ids(const char* who) {
  throw Error(std::string(who) +
              ": the surface has more than 4 billion vertices or triangles; crop the volume or "
              "select fewer labels");
}
inline uint32_t mesh_id_count(uint64_t n, const char* who) {
  if (n > std::numeric_limits<uint32_t>::max()) [[unlikely]]
    throw_too_many_ids(who);
  return static_cast<uint32_t>(n);
}

}  // namespace segmesh
