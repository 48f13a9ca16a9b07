// What the mesh readers and writers (stl_*, ply_*, obj_*, gltf_*) share. Internal to segmesh_io:
// the parts to write (part_list.hpp), errors naming the file, Part::transform applied to
// points and normals (Placement: a moved part written where it is), and number text. Each is O(1)
// per value; parts_to_write is one pass over the indices. Pieces: piece_writer.hpp; byte order:
// byte_order.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/scene.hpp"
#include "segmesh_io/part_list.hpp"

namespace segmesh::mesh_io {

// The material of a part read from a file that names none: light grey, dielectric.
inline Material neutral_material() { return {Rgb{0.8f, 0.8f, 0.8f}, 0.0f, 0.6f}; }

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& message);

// The whole file in memory. Throws Error when it is missing or unreadable.
std::string read_whole_file(const std::filesystem::path& file);

// Orthonormal rotation part with determinant +1 (within tol) and a bottom row of (0, 0, 0, 1).
bool is_rigid(const Transform& t, double tol = 1e-5);

// Where a part's vertices go in formats without a scene graph: its transform applied to each
// position and normal as it is written (no copy of the mesh), and the winding reversed when the
// transform mirrors.
class Placement {
 public:
  Placement() : transform_(identity_transform()), moved_(false), flips_(false) {}  // as it is
  explicit Placement(const Part& part);
  bool flips() const { return flips_; }
  Vec3f point(Vec3f p) const {
    return moved_ ? to_float(transform_point(transform_, to_double(p))) : p;
  }
  Vec3f normal(Vec3f n) const {
    return moved_ ? to_float(transform_normal(transform_, to_double(n))) : n;
  }
  // The corners of triangle t (indices 3t, 3t+1, 3t+2 of `mesh`) in the order they are written.
  std::array<uint32_t, 3> corners(const TriMesh& mesh, size_t t) const {
    const uint32_t* c = mesh.indices.data() + 3 * t;
    return flips_ ? std::array<uint32_t, 3>{c[0], c[2], c[1]}
                  : std::array<uint32_t, 3>{c[0], c[1], c[2]};
  }

 private:
  Transform transform_;
  bool moved_;
  bool flips_;
};

// The unit normal of triangle (a, b, c) taken counter-clockwise; zero for a degenerate triangle.
Vec3f face_normal(Vec3f a, Vec3f b, Vec3f c);

// The shortest decimal text that reads back as the same float ("0.7", not "0.699999988").
std::string format_float(float value);
// The double closest to that shortest text: what a JSON writer should print for a float setting.
double tidy(float value);

// `text` with line breaks and other control characters replaced by spaces, trimmed.
std::string one_line(std::string_view text);

uint8_t to_unorm8(float value);

}  // namespace segmesh::mesh_io
