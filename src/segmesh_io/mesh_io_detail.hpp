// Helpers shared by the mesh writers and readers (stl_*, ply_*, obj_*, gltf_*). Internal to
// segmesh_io: not part of the public API.
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "segmesh/error.hpp"
#include "segmesh/scene.hpp"

namespace segmesh::mesh_io {

// The parts a writer writes, in scene order. Pointers, so write_parts can hand one part to a
// writer without copying its mesh.
using PartList = std::vector<const Part*>;

// The parts with at least one triangle (empty parts are skipped by every writer). Checks each
// part's arrays (sizes agree, indices in range) and throws std::invalid_argument for a malformed
// mesh: that is a programming fault, not a user error.
PartList parts_to_write(const Scene& scene);
void check_mesh(const Part& part);

// The material of a part read from a file that names none: light grey, dielectric.
inline Material neutral_material() { return {Rgb{0.8f, 0.8f, 0.8f}, 0.0f, 0.6f}; }

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& message);

// The whole file in memory. Throws Error when it is missing or unreadable.
std::string read_whole_file(const std::filesystem::path& file);

bool is_identity(const Transform& t);
// Orthonormal rotation part with determinant +1 (within tol) and a bottom row of (0, 0, 0, 1).
bool is_rigid(const Transform& t, double tol = 1e-5);
Transform multiply(const Transform& a, const Transform& b);
Vec3d transform_point(const Transform& t, Vec3d p);
// Normals transform with the inverse transpose of the linear part; the result is unit length.
Vec3d transform_normal(const Transform& t, Vec3d n);
double linear_determinant(const Transform& t);

// A part's mesh with its transform applied (formats without a scene graph bake a moved part into
// its coordinates). No copy when the transform is the identity.
class PlacedMesh {
 public:
  explicit PlacedMesh(const Part& part);
  const TriMesh& mesh() const { return *mesh_; }

 private:
  TriMesh storage_;
  const TriMesh* mesh_;
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

// Little-endian binary I/O, independent of the host byte order.
template <class T>
T byteswap_value(T value) {
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(bytes[i], bytes[sizeof(T) - 1 - i]);
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

template <class T>
void append_le(std::string& out, T value) {
  if constexpr (std::endian::native == std::endian::big) value = byteswap_value(value);
  const size_t at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

template <class T>
T load_le(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) value = byteswap_value(value);
  return value;
}

template <class T>
T load_be(const char* p) {
  T value;
  std::memcpy(&value, p, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) value = byteswap_value(value);
  return value;
}

// Collects output in memory and hands it to the stream in large blocks: writers emit millions of
// tiny records, which a raw ofstream handles slowly.
class BlockWriter {
 public:
  explicit BlockWriter(std::ostream& out) : out_(out) { buffer_.reserve(kBlock + 256); }
  ~BlockWriter() = default;
  std::string& buffer() { return buffer_; }
  void maybe_flush() {
    if (buffer_.size() >= kBlock) flush();
  }
  void flush() {
    out_.write(buffer_.data(), static_cast<std::streamsize>(buffer_.size()));
    buffer_.clear();
  }

 private:
  static constexpr size_t kBlock = 1 << 20;
  std::ostream& out_;
  std::string buffer_;
};

}  // namespace segmesh::mesh_io
