#include "segmesh_io/obj_reader.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <map>
#include <optional>
#include <unordered_map>

#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/text.hpp"

namespace segmesh {

using namespace mesh_io;

namespace {

// Calls fn(line_number, line) for each line, without the line break.
template <class Fn>
void for_each_line(std::string_view text, Fn fn) {
  size_t pos = 0, line = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    fn(++line, text.substr(pos, end - pos));
    pos = end + 1;
  }
}

void read_mtl(const std::filesystem::path& mtl_file, std::map<std::string, Material>& out) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(mtl_file, ec)) return;
  const std::string text = read_whole_file(mtl_file);
  Material* current = nullptr;
  for_each_line(text, [&](size_t, std::string_view line) {
    std::string_view rest = line;
    const std::string_view key = next_word(rest);
    if (key == "newmtl") {
      current = &(out[std::string(trim(rest, kWhiteSpace))] = neutral_material());
      return;
    }
    if (!current) return;
    // Malformed values keep the default: a material is decoration, not geometry.
    if (key == "Kd") {
      float c[3];
      for (float& v : c) {
        if (!parse_number(next_word(rest), v)) return;
      }
      current->base_color = {c[0], c[1], c[2]};
    } else if (key == "Pr") {
      parse_number(next_word(rest), current->roughness);
    } else if (key == "Pm") {
      parse_number(next_word(rest), current->metallic);
    }
  });
}

struct PendingPart {
  Part part;
  std::string material;
  bool has_material = false;
  bool all_normals = true, all_colors = true;
  std::unordered_map<uint64_t, uint32_t> vertex_of;  // (position << 32 | normal + 1) -> local
};

// Orders a part's vertices as the file lists them (by position index, then normal index) rather
// than by first use, so an OBJ written by segmesh reads back with its original vertex numbering.
void renumber_in_file_order(PendingPart& pp) {
  std::vector<std::pair<uint64_t, uint32_t>> order(pp.vertex_of.begin(), pp.vertex_of.end());
  std::sort(order.begin(), order.end());
  std::vector<uint32_t> new_index(order.size());
  TriMesh& m = pp.part.mesh;
  TriMesh sorted;
  sorted.positions.reserve(order.size());
  sorted.normals.reserve(order.size());
  sorted.colors.reserve(order.size());
  for (size_t i = 0; i < order.size(); ++i) {
    const uint32_t old = order[i].second;
    new_index[old] = static_cast<uint32_t>(i);
    sorted.positions.push_back(m.positions[old]);
    sorted.normals.push_back(m.normals[old]);
    sorted.colors.push_back(m.colors[old]);
  }
  for (uint32_t& i : m.indices) i = new_index[i];
  m.positions = std::move(sorted.positions);
  m.normals = std::move(sorted.normals);
  m.colors = std::move(sorted.colors);
}

}  // namespace

Scene read_obj(std::string_view bytes, const std::filesystem::path& file) {
  bool has_o = false;
  for_each_line(bytes, [&](size_t, std::string_view line) {
    line = trim(line, kWhiteSpace);
    if (line.size() >= 2 && line[0] == 'o' && std::isspace(static_cast<unsigned char>(line[1]))) has_o = true;
  });

  std::vector<Vec3f> positions, normals;
  std::vector<Rgba8> colors;
  std::vector<bool> has_color;
  std::vector<std::string> mtllibs;
  Scene scene;
  std::vector<std::string> part_materials;
  std::optional<PendingPart> current;
  std::string pending_meta;

  const auto finish = [&]() {
    if (!current) return;
    PendingPart& pp = *current;
    if (!pp.part.mesh.empty()) {
      renumber_in_file_order(pp);
      if (!pp.all_normals) pp.part.mesh.normals.clear();
      if (!pp.all_colors) pp.part.mesh.colors.clear();
      scene.parts.push_back(std::move(pp.part));
      part_materials.push_back(pp.has_material ? pp.material : std::string());
    }
    current.reset();
  };
  const auto start = [&](std::string name) {
    finish();
    current.emplace();
    current->part.name = name.empty() ? file.stem().string() : std::move(name);
    current->part.material = neutral_material();
    // "# segmesh part label=1 component=1 role=bone voxels=0 visible=1", just before the "o".
    std::string_view meta = pending_meta;
    while (!meta.empty()) {
      const std::string_view word = next_word(meta);
      const size_t eq = word.find('=');
      if (eq == std::string_view::npos) continue;
      const std::string_view key = word.substr(0, eq), value = word.substr(eq + 1);
      Part& p = current->part;
      if (key == "label") parse_number(value, p.label);
      else if (key == "component") parse_number(value, p.component);
      else if (key == "voxels") parse_number(value, p.voxels);
      else if (key == "role") p.role = parse_role(value).value_or(Role::other);
      else if (key == "visible") p.visible = value != "0";
    }
    pending_meta.clear();
  };

  for_each_line(bytes, [&](size_t line_no, std::string_view line) {
    const auto error = [&](const std::string& what) {
      fail(file, "line " + std::to_string(line_no) + ": " + what + " ('" +
                     one_line(trim(line, kWhiteSpace).substr(0, 60)) + "')");
    };
    std::string_view rest = line;
    const std::string_view key = next_word(rest);
    if (key.empty()) return;
    if (key == "v") {
      float c[6];
      int n = 0;
      for (; n < 6; ++n) {
        const std::string_view word = next_word(rest);
        if (word.empty()) break;
        if (!parse_number(word, c[n])) error("bad number in a vertex");
      }
      if (n < 3) error("a vertex needs x y z");
      positions.push_back({c[0], c[1], c[2]});
      has_color.push_back(n == 6);
      colors.push_back(n == 6 ? Rgba8{to_unorm8(c[3]), to_unorm8(c[4]), to_unorm8(c[5]), 255}
                              : Rgba8{255, 255, 255, 255});
    } else if (key == "vn") {
      float c[3];
      for (float& v : c) {
        if (!parse_number(next_word(rest), v)) error("a normal needs three numbers");
      }
      normals.push_back({c[0], c[1], c[2]});
    } else if (key == "f") {
      if (!current) start(std::string());
      PendingPart& pp = *current;
      TriMesh& mesh = pp.part.mesh;
      uint32_t corner[3] = {0, 0, 0};
      int corners = 0;
      while (true) {
        const std::string_view word = next_word(rest);
        if (word.empty()) break;
        // "v", "v/t", "v//n" or "v/t/n"; negative indices count back from the latest.
        const size_t s1 = word.find('/');
        const size_t s2 = s1 == std::string_view::npos ? s1 : word.find('/', s1 + 1);
        const auto resolve = [&](std::string_view text, size_t count, const char* what) -> uint64_t {
          int64_t i = 0;
          if (!parse_number(text, i) || i == 0) error(std::string("bad ") + what + " index");
          const int64_t resolved = i < 0 ? static_cast<int64_t>(count) + i : i - 1;
          if (resolved < 0 || resolved >= static_cast<int64_t>(count)) {
            error(std::string(what) + " index " + std::to_string(i) + " is out of range (" +
                  std::to_string(count) + " defined so far)");
          }
          return static_cast<uint64_t>(resolved);
        };
        const uint64_t v = resolve(word.substr(0, s1), positions.size(), "vertex");
        uint64_t n_plus_1 = 0;
        if (s2 != std::string_view::npos && s2 + 1 < word.size()) {
          n_plus_1 = resolve(word.substr(s2 + 1), normals.size(), "normal") + 1;
        }
        const auto [it, inserted] =
            pp.vertex_of.try_emplace((v << 32) | n_plus_1, static_cast<uint32_t>(mesh.positions.size()));
        if (inserted) {
          mesh.positions.push_back(positions[v]);
          mesh.normals.push_back(n_plus_1 ? normals[n_plus_1 - 1] : Vec3f{});
          mesh.colors.push_back(colors[v]);
          pp.all_normals = pp.all_normals && n_plus_1 != 0;
          pp.all_colors = pp.all_colors && has_color[v];
        }
        const uint32_t index = it->second;
        if (corners < 2) {
          corner[corners] = index;
        } else {
          mesh.indices.insert(mesh.indices.end(), {corner[0], corner[1], index});
          corner[1] = index;
        }
        ++corners;
      }
      if (corners < 3) error("a face needs at least 3 corners");
    } else if (key == "o" || (key == "g" && !has_o)) {
      start(one_line(trim(rest, kWhiteSpace)));
    } else if (key == "usemtl") {
      if (!current) start(std::string());
      if (!current->has_material) {
        current->material = std::string(trim(rest, kWhiteSpace));
        current->has_material = true;
      }
    } else if (key == "mtllib") {
      mtllibs.emplace_back(trim(rest, kWhiteSpace));
    } else if (key == "#") {
      if (next_word(rest) == "segmesh" && next_word(rest) == "part") pending_meta = std::string(rest);
    }
  });
  finish();

  std::map<std::string, Material> materials;
  for (const std::string& lib : mtllibs) read_mtl(file.parent_path() / lib, materials);
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    const auto it = materials.find(part_materials[i]);
    if (it != materials.end()) scene.parts[i].material = it->second;
  }
  return scene;
}

}  // namespace segmesh
