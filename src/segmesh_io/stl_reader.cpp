#include "segmesh_io/stl_reader.hpp"

#include <charconv>
#include <unordered_map>

#include "segmesh/position_key.hpp"
#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"

namespace segmesh {

using namespace mesh_io;

namespace {

// Welds corners by exact coordinates (position_key.hpp).
class Welder {
 public:
  explicit Welder(TriMesh& mesh) : mesh_(mesh) {}
  void add_corner(Vec3f p) {
    const auto [it, inserted] = map_.try_emplace(position_key(p), static_cast<uint32_t>(mesh_.positions.size()));
    if (inserted) mesh_.positions.push_back(p);
    mesh_.indices.push_back(it->second);
  }
  void reserve(size_t triangles) {
    mesh_.indices.reserve(3 * triangles);
    map_.reserve(triangles / 2 + 4);
  }

 private:
  TriMesh& mesh_;
  std::unordered_map<PositionKey, uint32_t, PositionKeyHash> map_;
};

Part make_part(std::string name) {
  Part part;
  part.name = std::move(name);
  part.material = neutral_material();
  return part;
}

std::string header_name(std::string_view header, const std::filesystem::path& file) {
  std::string text(header.substr(0, std::min<size_t>(header.find('\0'), header.size())));
  text = one_line(text);
  const std::string_view prefix = "segmesh ", suffix = " SPACE=LPS mm";
  if (text.size() > prefix.size() + suffix.size() && text.starts_with(prefix) &&
      text.ends_with(suffix)) {
    return text.substr(prefix.size(), text.size() - prefix.size() - suffix.size());
  }
  return file.stem().string();
}

Scene read_binary(std::string_view bytes, const std::filesystem::path& file, uint32_t count) {
  Scene scene;
  Part part = make_part(header_name(bytes.substr(0, 80), file));
  Welder welder(part.mesh);
  welder.reserve(count);
  const char* p = bytes.data() + 84;
  for (uint32_t t = 0; t < count; ++t, p += 50) {
    for (int c = 0; c < 3; ++c) {
      const char* v = p + 12 + 12 * c;
      welder.add_corner({load_le<float>(v), load_le<float>(v + 4), load_le<float>(v + 8)});
    }
  }
  scene.parts.push_back(std::move(part));
  return scene;
}

class AsciiParser {
 public:
  AsciiParser(std::string_view text, const std::filesystem::path& file) : s_(text), file_(file) {}

  Scene parse() {
    Scene scene;
    expect("solid");
    while (true) {
      Part part = make_part(rest_of_line());
      if (part.name.empty()) part.name = file_.stem().string();
      Welder welder(part.mesh);
      while (true) {
        const std::string_view word = token();
        if (word == "endsolid") break;
        if (word != "facet") error("expected 'facet' or 'endsolid'", word);
        expect("normal");
        for (int i = 0; i < 3; ++i) number();
        expect("outer");
        expect("loop");
        for (int c = 0; c < 3; ++c) {
          expect("vertex");
          const float x = number(), y = number(), z = number();
          welder.add_corner({x, y, z});
        }
        expect("endloop");
        expect("endfacet");
      }
      rest_of_line();
      scene.parts.push_back(std::move(part));
      skip_space();
      if (pos_ >= s_.size()) break;
      expect("solid");
    }
    return scene;
  }

 private:
  void skip_space() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) {
      if (s_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string_view token() {
    skip_space();
    const size_t start = pos_;
    while (pos_ < s_.size() && !std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
    return s_.substr(start, pos_ - start);
  }
  std::string rest_of_line() {
    const size_t start = pos_;
    while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
    return one_line(s_.substr(start, pos_ - start));
  }
  void expect(std::string_view word) {
    const std::string_view got = token();
    if (got != word) error("expected '" + std::string(word) + "'", got);
  }
  float number() {
    std::string_view t = token();
    if (!t.empty() && t.front() == '+') t.remove_prefix(1);
    float v = 0;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size()) error("expected a number", t);
    return v;
  }
  [[noreturn]] void error(const std::string& what, std::string_view got) {
    const std::string found = got.empty() ? "the end of the file" : "'" + one_line(got.substr(0, 40)) + "'";
    fail(file_, "not a valid ASCII STL file (line " + std::to_string(line_) + ": " + what +
                    ", found " + found + "); the file may be truncated");
  }

  std::string_view s_;
  const std::filesystem::path& file_;
  size_t pos_ = 0;
  size_t line_ = 1;
};

}  // namespace

Scene read_stl(std::string_view bytes, const std::filesystem::path& file) {
  if (bytes.size() >= 84) {
    const uint32_t count = load_le<uint32_t>(bytes.data() + 80);
    const uint64_t expected = 84 + 50 * uint64_t{count};
    if (bytes.size() == expected) return read_binary(bytes, file, count);
    if (!bytes.starts_with("solid")) {
      fail(file, "binary STL header says " + std::to_string(count) + " triangles (" +
                     std::to_string(expected) + " bytes) but the file has " +
                     std::to_string(bytes.size()) + " bytes; it is truncated or corrupt");
    }
  } else if (!bytes.starts_with("solid")) {
    fail(file, "too short for a binary STL file (" + std::to_string(bytes.size()) +
                   " bytes, the header alone is 84) and not ASCII STL either");
  }
  return AsciiParser(bytes, file).parse();
}

}  // namespace segmesh
