#include "segmesh_io/atlas_writer.hpp"

#include <array>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "segmesh_io/atomic_file.hpp"
#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/glb_document.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"
#include "segmesh_io/detail/ply_layout.hpp"
#include "segmesh_io/mesh_format.hpp"
#include "segmesh_io/part_list.hpp"

namespace segmesh {

namespace fs = std::filesystem;
using namespace mesh_io;

namespace {

using Sides = std::array<uint32_t, 2>;

// Material m's name: "background" for 0, else the name of part m - 1.
std::string material_name(const Scene& scene, uint32_t m) {
  return m == 0 ? "background" : scene.parts[m - 1].name;
}

// The surface's arrays agree with each other and with the scene's parts.
void check_surface(const Scene& scene, const LabelledSurface& s) {
  const auto bad = [](const std::string& what) {
    throw std::invalid_argument("conforming surface: " + what);
  };
  if (s.mesh.indices.size() % 3 != 0) bad("index count is not a multiple of 3");
  if (s.sides.size() != s.mesh.triangle_count()) bad("sides and triangles differ in number");
  for (uint32_t i : s.mesh.indices) {
    if (i >= s.mesh.vertex_count()) bad("index out of range");
  }
  for (const Sides& pair : s.sides) {
    if (pair[0] > scene.parts.size() || pair[1] > scene.parts.size()) {
      bad("a material beyond the scene's " + std::to_string(scene.parts.size()) + " parts");
    }
    if (pair[0] == pair[1]) bad("a triangle with the same material on both sides");
  }
}

// The surface of a conforming scene whose parts touch nowhere, which extract_parts meshed one by
// one (Scene::conforming without a surface): every part's shell, each of its triangles between the
// part (inside) and the background (outside), as the one surface would have given them.
LabelledSurface separate_parts_surface(const Scene& scene) {
  LabelledSurface s;
  s.part_count = scene.parts.size();
  for (uint32_t p = 0; p < scene.parts.size(); ++p) {
    check_mesh(scene.parts[p]);
    const TriMesh& m = scene.parts[p].mesh;
    const uint32_t first = static_cast<uint32_t>(s.mesh.positions.size());
    mesh_id_count(uint64_t{first} + m.positions.size(), "atlas");
    s.mesh.positions.insert(s.mesh.positions.end(), m.positions.begin(), m.positions.end());
    for (uint32_t i : m.indices) s.mesh.indices.push_back(first + i);
    s.sides.insert(s.sides.end(), m.triangle_count(), Sides{p + 1, 0});
  }
  return s;
}

void write_atlas_ply(const Scene& scene, const LabelledSurface& s, const fs::path& file,
                     std::ostream& out) {
  const TriMesh& m = s.mesh;
  if (m.vertex_count() > size_t(std::numeric_limits<int32_t>::max())) {
    fail(file, "an atlas PLY with int indices holds at most 2147483647 vertices; this surface has " +
                   std::to_string(m.vertex_count()) + "; crop the volume or select fewer labels");
  }
  std::string header = ply_header_start();
  header += "comment atlas: faces separate material inside from material outside, wound "
            "counter-clockwise seen from outside\n";
  for (uint32_t material = 0; material <= scene.parts.size(); ++material) {
    header += "comment material " + std::to_string(material) + " " +
              one_line(material_name(scene, material)) + "\n";
  }
  header += ply_vertex_element(m.vertex_count(), PlyVertexLayout{});
  header += "element face " + std::to_string(m.triangle_count()) + "\n";
  header += "property list uchar int vertex_indices\nproperty int inside\nproperty int outside\n";
  header += "end_header\n";

  PieceList pieces;
  pieces.text(std::move(header));
  add_ply_vertices(pieces, m, Placement(), PlyVertexLayout{});
  pieces.records(m.triangle_count(), 21, [&m, &s](size_t t, char* p) {
    *p++ = 3;
    for (size_t c = 3 * t; c < 3 * t + 3; ++c) p = put_le<int32_t>(p, int32_t(m.indices[c]));
    p = put_le<int32_t>(p, int32_t(s.sides[t][0]));
    return put_le<int32_t>(p, int32_t(s.sides[t][1]));
  });
  pieces.write(out);
}

// The triangles' indices grouped by (inside, outside) pair, pairs ascending, surface order kept
// within a pair; `pairs` receives each pair with its first triangle and triangle count.
struct PairGroup {
  Sides pair;
  size_t first = 0, count = 0;
};
std::vector<uint32_t> group_by_pair(const LabelledSurface& s, std::vector<PairGroup>& pairs) {
  std::map<Sides, size_t> next;  // per pair: its triangle count, then where its next one goes
  for (const Sides& pair : s.sides) ++next[pair];
  size_t first = 0;
  for (auto& [pair, n] : next) {
    pairs.push_back(PairGroup{pair, first, n});
    n = first;
    first += pairs.back().count;
  }
  std::vector<uint32_t> grouped(s.mesh.indices.size());
  for (size_t t = 0; t < s.sides.size(); ++t) {
    const size_t at = 3 * next[s.sides[t]]++;
    for (size_t c = 0; c < 3; ++c) grouped[at + c] = s.mesh.indices[3 * t + c];
  }
  return grouped;
}

void write_atlas_glb(const Scene& scene, const LabelledSurface& s, std::ostream& out) {
  std::vector<PairGroup> pairs;
  const std::vector<uint32_t> grouped = group_by_pair(s, pairs);
  GlbScene glb;
  GlbMesh mesh{.name = "atlas", .vertices = &s.mesh};
  std::map<uint32_t, size_t> material_of_part;  // material number -> index in glb.materials
  for (const PairGroup& g : pairs) {
    const auto [inside, outside] = g.pair;
    const uint32_t shown = inside != 0 ? inside : outside;  // not both: check_surface
    auto [it, added] = material_of_part.try_emplace(shown, glb.materials.size());
    if (added) {
      const Part& part = scene.parts[shown - 1];
      glb.materials.push_back(GlbMaterial{part.name, part.material});
    }
    mesh.primitives.push_back(GlbPrimitive{
        std::span<const uint32_t>(grouped).subspan(3 * g.first, 3 * g.count), it->second,
        {{"inside", material_name(scene, inside)},
         {"outside", material_name(scene, outside)},
         {"inside_material", int64_t{inside}},
         {"outside_material", int64_t{outside}}}});
  }
  glb.meshes.push_back(std::move(mesh));
  write_glb_scene(glb, out);
}

}  // namespace

AtlasFormat atlas_format(const fs::path& file) {
  const std::optional<MeshFormat> format = mesh_format_from_path(file);
  if (format == MeshFormat::ply) return AtlasFormat::ply;
  if (format == MeshFormat::glb) return AtlasFormat::glb;
  fail(file, "an atlas is written as .ply or .glb, not \"" + file.extension().string() +
                 "\"; name the file .ply or .glb");
}

void write_atlas(const Scene& scene, const fs::path& file) {
  const AtlasFormat format = atlas_format(file);
  std::optional<LabelledSurface> separate;
  if (!scene.surface) {
    if (!scene.conforming) {
      fail(file, "the scene was meshed with independent surfaces, not one surface to write as an "
                 "atlas; --atlas needs --surfaces conforming");
    }
    separate = separate_parts_surface(scene);
  }
  const LabelledSurface& surface = scene.surface ? *scene.surface : *separate;
  check_surface(scene, surface);
  require_parent_folder(file);
  AtomicFile atomic(file);
  if (format == AtlasFormat::ply) {
    write_atlas_ply(scene, surface, file, atomic.stream());
  } else {
    write_atlas_glb(scene, surface, atomic.stream());
  }
  atomic.commit();
}

}  // namespace segmesh
