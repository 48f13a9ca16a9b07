#include "segmesh_io/detail/mesh_io_common.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <system_error>

namespace segmesh::mesh_io {

namespace fs = std::filesystem;

void fail(const fs::path& file, const std::string& message) {
  throw Error(file.string() + ": " + message);
}

std::string read_whole_file(const fs::path& file) {
  std::error_code ec;
  if (!fs::exists(file, ec)) fail(file, "no such file");
  if (fs::is_directory(file, ec)) fail(file, "is a folder, not a mesh file");
  const auto size = fs::file_size(file, ec);
  if (ec) fail(file, "cannot read the file size (" + ec.message() + ")");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open the file for reading; check its permissions");
  std::string bytes(static_cast<size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(size));
  if (static_cast<uintmax_t>(in.gcount()) != size) fail(file, "could not read the whole file");
  return bytes;
}

bool is_rigid(const Transform& t, double tol) {
  if (std::abs(t[3]) > tol || std::abs(t[7]) > tol || std::abs(t[11]) > tol ||
      std::abs(t[15] - 1) > tol) {
    return false;
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      double d = 0;
      for (int r = 0; r < 3; ++r) d += t[4 * a + r] * t[4 * b + r];
      if (std::abs(d - (a == b ? 1.0 : 0.0)) > tol) return false;
    }
  }
  return linear_determinant(t) > 0;
}

Placement::Placement(const Part& part)
    : transform_(part.transform),
      moved_(!is_identity(part.transform)),
      flips_(moved_ && linear_determinant(part.transform) < 0) {}

Vec3f face_normal(Vec3f a, Vec3f b, Vec3f c) {
  const Vec3d pa = to_double(a);
  const Vec3d n = cross(to_double(b) - pa, to_double(c) - pa);
  const double len = norm(n);
  return len > 0 ? to_float((1.0 / len) * n) : Vec3f{};
}

std::string format_float(float value) {
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  return std::string(text, result.ptr);
}

double tidy(float value) {
  if (!std::isfinite(value)) return 0;
  const std::string text = format_float(value);
  double d = 0;
  std::from_chars(text.data(), text.data() + text.size(), d);
  return d;
}

std::string one_line(std::string_view text) {
  std::string out(text);
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  }
  const auto first = out.find_first_not_of(' ');
  if (first == std::string::npos) return {};
  const auto last = out.find_last_not_of(' ');
  return out.substr(first, last - first + 1);
}

uint8_t to_unorm8(float value) {
  if (!(value > 0)) return 0;
  if (value >= 1) return 255;
  return static_cast<uint8_t>(std::lround(value * 255.0f));
}

}  // namespace segmesh::mesh_io
