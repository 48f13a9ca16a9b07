#include "segmesh_io/ply_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/text.hpp"

namespace segmesh {

using namespace mesh_io;

namespace {

enum class Encoding { ascii, binary_le, binary_be };
enum class Type { i8, u8, i16, u16, i32, u32, f32, f64 };

size_t type_size(Type t) {
  switch (t) {
    case Type::i8: case Type::u8: return 1;
    case Type::i16: case Type::u16: return 2;
    case Type::i32: case Type::u32: case Type::f32: return 4;
    case Type::f64: return 8;
  }
  return 1;
}

std::optional<Type> parse_type(std::string_view s) {
  if (s == "char" || s == "int8") return Type::i8;
  if (s == "uchar" || s == "uint8") return Type::u8;
  if (s == "short" || s == "int16") return Type::i16;
  if (s == "ushort" || s == "uint16") return Type::u16;
  if (s == "int" || s == "int32") return Type::i32;
  if (s == "uint" || s == "uint32") return Type::u32;
  if (s == "float" || s == "float32") return Type::f32;
  if (s == "double" || s == "float64") return Type::f64;
  return std::nullopt;
}

struct Property {
  std::string name;
  Type type = Type::f32;
  bool list = false;
  Type count_type = Type::u8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> props;
  int find(std::string_view n) const {
    for (size_t i = 0; i < props.size(); ++i) {
      if (props[i].name == n) return static_cast<int>(i);
    }
    return -1;
  }
};

[[noreturn]] void bad_ply_header(const std::filesystem::path& file, const std::string& why) {
  fail(file, "not a valid PLY header (" + why + ")");
}

struct PartComment {
  Part part;
  uint64_t vertices = 0, faces = 0;
};

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  for (std::string_view word; !(word = next_word(line)).empty();) words.push_back(word);
  return words;
}

// "comment part vertices=8 faces=12 ... name=rest of line"; nullopt when malformed.
std::optional<PartComment> parse_part_comment(std::string_view text) {
  PartComment pc;
  pc.part.material = neutral_material();
  const size_t name_at = text.find(" name=");
  if (name_at != std::string_view::npos) pc.part.name = one_line(text.substr(name_at + 6));
  bool have_v = false, have_f = false;
  for (std::string_view word : split_words(text.substr(0, name_at))) {
    const size_t eq = word.find('=');
    if (eq == std::string_view::npos) continue;
    const std::string_view key = word.substr(0, eq), value = word.substr(eq + 1);
    bool ok = true;
    if (key == "vertices") ok = have_v = parse_number(value, pc.vertices);
    else if (key == "faces") ok = have_f = parse_number(value, pc.faces);
    else if (key == "label") ok = parse_number(value, pc.part.label);
    else if (key == "component") ok = parse_number(value, pc.part.component);
    else if (key == "voxels") ok = parse_number(value, pc.part.voxels);
    else if (key == "visible") pc.part.visible = value != "0";
    else if (key == "role") pc.part.role = parse_role(value).value_or(Role::other);
    else if (key == "metallic") ok = parse_number(value, pc.part.material.metallic);
    else if (key == "roughness") ok = parse_number(value, pc.part.material.roughness);
    else if (key == "color") {
      float rgb[3];
      size_t start = 0;
      for (int c = 0; c < 3 && ok; ++c) {
        const size_t end = c < 2 ? value.find(',', start) : value.size();
        ok = end != std::string_view::npos && parse_number(value.substr(start, end - start), rgb[c]);
        start = end + 1;
      }
      if (ok) pc.part.material.base_color = {rgb[0], rgb[1], rgb[2]};
    }
    if (!ok) return std::nullopt;
  }
  if (!have_v || !have_f) return std::nullopt;
  return pc;
}

class Cursor {
 public:
  Cursor(std::string_view data, Encoding enc, const std::filesystem::path& file)
      : d_(data), enc_(enc), file_(file) {}

  size_t remaining() const { return d_.size() - pos_; }

  double scalar(Type t) {
    if (enc_ == Encoding::ascii) return ascii_scalar();
    const size_t n = type_size(t);
    if (remaining() < n) truncated();
    const char* p = d_.data() + pos_;
    pos_ += n;
    const bool le = enc_ == Encoding::binary_le;
    switch (t) {
      case Type::i8: return static_cast<int8_t>(*p);
      case Type::u8: return static_cast<uint8_t>(*p);
      case Type::i16: return le ? load_le<int16_t>(p) : load_be<int16_t>(p);
      case Type::u16: return le ? load_le<uint16_t>(p) : load_be<uint16_t>(p);
      case Type::i32: return le ? load_le<int32_t>(p) : load_be<int32_t>(p);
      case Type::u32: return le ? load_le<uint32_t>(p) : load_be<uint32_t>(p);
      case Type::f32: return le ? load_le<float>(p) : load_be<float>(p);
      case Type::f64: return le ? load_le<double>(p) : load_be<double>(p);
    }
    return 0;
  }

  // A list length or an index: a non-negative integer.
  uint64_t count(Type t, const char* what) {
    const double v = scalar(t);
    if (!(v >= 0) || v != std::floor(v) || v > 4294967295.0) {
      fail(file_, std::string("PLY ") + what + " " + std::to_string(v) + " is not a valid count");
    }
    return static_cast<uint64_t>(v);
  }

  [[noreturn]] void truncated() {
    fail(file_, "PLY data ends early: the file is truncated or its header's element counts are wrong");
  }

 private:
  double ascii_scalar() {
    while (pos_ < d_.size() && std::isspace(static_cast<unsigned char>(d_[pos_]))) ++pos_;
    const size_t start = pos_;
    while (pos_ < d_.size() && !std::isspace(static_cast<unsigned char>(d_[pos_]))) ++pos_;
    if (pos_ == start) truncated();
    double v = 0;
    const std::string_view token = d_.substr(start, pos_ - start);
    if (!parse_number(token, v)) {
      fail(file_, "PLY ASCII data holds '" + one_line(token.substr(0, 40)) + "' where a number belongs");
    }
    return v;
  }

  std::string_view d_;
  size_t pos_ = 0;
  Encoding enc_;
  const std::filesystem::path& file_;
};

}  // namespace

Scene read_ply(std::string_view bytes, const std::filesystem::path& file) {
  if (!bytes.starts_with("ply\n") && !bytes.starts_with("ply\r\n")) bad_ply_header(file, "missing 'ply'");
  size_t end = bytes.find("end_header");
  while (end != std::string_view::npos && bytes[end - 1] != '\n') end = bytes.find("end_header", end + 1);
  if (end == std::string_view::npos) bad_ply_header(file, "no end_header line; the file is truncated");
  size_t data_start = bytes.find('\n', end);
  if (data_start == std::string_view::npos) bad_ply_header(file, "nothing after end_header");
  ++data_start;

  std::optional<Encoding> encoding;
  std::vector<Element> elements;
  std::vector<PartComment> part_comments;
  bool part_comments_ok = true;
  std::istringstream header{std::string(bytes.substr(0, end))};
  std::string line;
  std::getline(header, line);
  while (std::getline(header, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto w = split_words(line);
    if (w.empty()) continue;
    if (w[0] == "format") {
      if (w.size() < 2) bad_ply_header(file, "format line without a format");
      if (w[1] == "ascii") encoding = Encoding::ascii;
      else if (w[1] == "binary_little_endian") encoding = Encoding::binary_le;
      else if (w[1] == "binary_big_endian") encoding = Encoding::binary_be;
      else bad_ply_header(file, "unknown format '" + one_line(w[1]) + "'");
    } else if (w[0] == "comment") {
      if (w.size() >= 2 && w[1] == "part") {
        auto pc = parse_part_comment(std::string_view(line).substr(line.find("part") + 4));
        if (pc) part_comments.push_back(std::move(*pc));
        else part_comments_ok = false;
      }
    } else if (w[0] == "obj_info") {
    } else if (w[0] == "element") {
      Element e;
      if (w.size() != 3 || !parse_number(w[2], e.count)) bad_ply_header(file, "bad element line '" + one_line(line) + "'");
      e.name = std::string(w[1]);
      elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      if (elements.empty()) bad_ply_header(file, "property before any element");
      Property p;
      std::optional<Type> t;
      if (w.size() == 5 && w[1] == "list") {
        const auto ct = parse_type(w[2]);
        t = parse_type(w[3]);
        if (!ct || !t || *ct == Type::f32 || *ct == Type::f64) bad_ply_header(file, "bad list property '" + one_line(line) + "'");
        p.list = true;
        p.count_type = *ct;
        p.name = std::string(w[4]);
      } else if (w.size() == 3) {
        t = parse_type(w[1]);
        p.name = std::string(w[2]);
      }
      if (!t) bad_ply_header(file, "bad property line '" + one_line(line) + "'");
      p.type = *t;
      elements.back().props.push_back(std::move(p));
    } else {
      bad_ply_header(file, "unknown keyword '" + one_line(w[0]) + "'");
    }
  }
  if (!encoding) bad_ply_header(file, "no format line");

  // Every element's count against the bytes left at the smallest encoding of one item (ASCII: one
  // character and one separator per value), before anything is allocated.
  const uint64_t data_bytes = bytes.size() - data_start;
  uint64_t needed = 0;
  for (const Element& e : elements) {
    uint64_t min_item = 0;
    for (const Property& p : e.props) {
      min_item += *encoding == Encoding::ascii ? 2 : type_size(p.list ? p.count_type : p.type);
    }
    if (min_item == 0) {
      if (e.count > data_bytes) fail(file, "PLY element '" + e.name + "' claims " + std::to_string(e.count) + " items with no properties");
      continue;
    }
    if (e.count > (data_bytes + 1) / min_item || needed + e.count * min_item > data_bytes + 1) {
      fail(file, "PLY header claims " + std::to_string(e.count) + " " + one_line(e.name) +
                     " items, more than the " + std::to_string(data_bytes) +
                     " data bytes can hold; the file is truncated or its header is wrong");
    }
    needed += e.count * min_item;
  }

  const Element* vertex_el = nullptr;
  for (const Element& e : elements) {
    if (e.name == "vertex" && !vertex_el) vertex_el = &e;
  }
  if (!vertex_el) fail(file, "PLY file has no vertex element");
  const int ix = vertex_el->find("x"), iy = vertex_el->find("y"), iz = vertex_el->find("z");
  if (ix < 0 || iy < 0 || iz < 0) fail(file, "PLY vertex element lacks x, y or z");
  const uint64_t vertex_count = vertex_el->count;
  if (vertex_count > std::numeric_limits<uint32_t>::max()) fail(file, "PLY file has too many vertices");

  TriMesh mesh;
  bool all_triangles = true;
  Cursor cur(bytes.substr(data_start), *encoding, file);
  for (const Element& e : elements) {
    if (&e == vertex_el) {
      const int inx = e.find("nx"), iny = e.find("ny"), inz = e.find("nz");
      int ir = e.find("red"), ig = e.find("green"), ib = e.find("blue"), ia = e.find("alpha");
      if (ir < 0) ir = e.find("diffuse_red"), ig = e.find("diffuse_green"), ib = e.find("diffuse_blue"), ia = e.find("diffuse_alpha");
      const bool normals = inx >= 0 && iny >= 0 && inz >= 0;
      const bool colors = ir >= 0 && ig >= 0 && ib >= 0;
      mesh.positions.resize(e.count);
      if (normals) mesh.normals.resize(e.count);
      if (colors) mesh.colors.assign(e.count, Rgba8{255, 255, 255, 255});
      std::vector<double> values(e.props.size());
      for (uint64_t v = 0; v < e.count; ++v) {
        for (size_t p = 0; p < e.props.size(); ++p) {
          const Property& prop = e.props[p];
          if (prop.list) {
            const uint64_t n = cur.count(prop.count_type, "list length");
            for (uint64_t k = 0; k < n; ++k) cur.scalar(prop.type);
            values[p] = 0;
          } else {
            values[p] = cur.scalar(prop.type);
          }
        }
        mesh.positions[v] = {float(values[ix]), float(values[iy]), float(values[iz])};
        if (normals) mesh.normals[v] = {float(values[inx]), float(values[iny]), float(values[inz])};
        if (colors) {
          const auto channel = [&](int i) -> uint8_t {
            const Type t = e.props[i].type;
            if (t == Type::f32 || t == Type::f64) return to_unorm8(float(values[i]));
            return static_cast<uint8_t>(std::clamp(values[i], 0.0, 255.0));
          };
          mesh.colors[v] = {channel(ir), channel(ig), channel(ib), ia >= 0 ? channel(ia) : uint8_t{255}};
        }
      }
    } else if (e.name == "face") {
      int list = e.find("vertex_indices");
      if (list < 0) list = e.find("vertex_index");
      if (list >= 0 && !e.props[list].list) fail(file, "PLY face property '" + e.props[list].name + "' is not a list");
      mesh.indices.reserve(3 * e.count);
      for (uint64_t f = 0; f < e.count; ++f) {
        for (size_t p = 0; p < e.props.size(); ++p) {
          const Property& prop = e.props[p];
          if (!prop.list) {
            cur.scalar(prop.type);
            continue;
          }
          const uint64_t n = cur.count(prop.count_type, "list length");
          if (static_cast<int>(p) != list) {
            for (uint64_t k = 0; k < n; ++k) cur.scalar(prop.type);
            continue;
          }
          if (n != 3) all_triangles = false;
          uint32_t first = 0, previous = 0;
          for (uint64_t k = 0; k < n; ++k) {
            const uint64_t index = cur.count(prop.type, "vertex index");
            if (index >= vertex_count) {
              fail(file, "PLY face " + std::to_string(f) + " uses vertex " + std::to_string(index) +
                             " but the file has only " + std::to_string(vertex_count) + " vertices");
            }
            const auto i = static_cast<uint32_t>(index);
            if (k == 0) first = i;
            else if (k >= 2) mesh.indices.insert(mesh.indices.end(), {first, previous, i});
            previous = i;
          }
        }
      }
    } else {
      for (uint64_t i = 0; i < e.count; ++i) {
        for (const Property& prop : e.props) {
          const uint64_t n = prop.list ? cur.count(prop.count_type, "list length") : 1;
          for (uint64_t k = 0; k < n; ++k) cur.scalar(prop.type);
        }
      }
    }
  }

  Scene scene;
  // Split into the parts the comments describe only when they account for every vertex and
  // triangle and each part's triangles stay within its own vertices; otherwise one part.
  uint64_t sum_v = 0, sum_f = 0;
  for (const PartComment& pc : part_comments) sum_v += pc.vertices, sum_f += pc.faces;
  bool split = part_comments_ok && !part_comments.empty() && all_triangles &&
               sum_v == mesh.positions.size() && sum_f == mesh.triangle_count();
  if (split) {
    uint64_t v0 = 0, f0 = 0;
    for (const PartComment& pc : part_comments) {
      for (uint64_t i = 3 * f0; i < 3 * (f0 + pc.faces) && split; ++i) {
        split = mesh.indices[i] >= v0 && mesh.indices[i] < v0 + pc.vertices;
      }
      v0 += pc.vertices, f0 += pc.faces;
    }
  }
  if (!split) {
    Part part;
    part.name = file.stem().string();
    part.material = neutral_material();
    part.mesh = std::move(mesh);
    scene.parts.push_back(std::move(part));
    return scene;
  }
  uint64_t v0 = 0, f0 = 0;
  for (PartComment& pc : part_comments) {
    Part part = std::move(pc.part);
    if (part.name.empty()) part.name = "part_" + std::to_string(scene.parts.size() + 1);
    TriMesh& m = part.mesh;
    m.positions.assign(mesh.positions.begin() + v0, mesh.positions.begin() + v0 + pc.vertices);
    if (!mesh.normals.empty()) m.normals.assign(mesh.normals.begin() + v0, mesh.normals.begin() + v0 + pc.vertices);
    if (!mesh.colors.empty()) m.colors.assign(mesh.colors.begin() + v0, mesh.colors.begin() + v0 + pc.vertices);
    // The writer fills parts without colours with their material colour; that is not data.
    const Rgba8 material_color{to_unorm8(part.material.base_color.r), to_unorm8(part.material.base_color.g),
                               to_unorm8(part.material.base_color.b), 255};
    if (std::all_of(m.colors.begin(), m.colors.end(), [&](const Rgba8& c) { return c == material_color; })) {
      m.colors.clear();
    }
    m.indices.assign(mesh.indices.begin() + 3 * f0, mesh.indices.begin() + 3 * (f0 + pc.faces));
    for (uint32_t& i : m.indices) i -= static_cast<uint32_t>(v0);
    v0 += pc.vertices, f0 += pc.faces;
    scene.parts.push_back(std::move(part));
  }
  return scene;
}

}  // namespace segmesh
