#include "segmesh_io/obj_writer.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstring>
#include <cctype>
#include <cmath>

#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"
#include "segmesh_io/detail/text.hpp"

namespace segmesh {

using namespace mesh_io;

namespace {

std::string material_name(const std::string& part_name, UniqueNames& used) {
  std::string base = one_line(part_name);
  for (char& c : base) {
    if (std::isspace(static_cast<unsigned char>(c))) c = '_';
  }
  if (base.empty()) base = "part";
  return used.make(base);
}

// "<tag> x y z\n" with each number in its shortest exact form; at most kMaxVecLine bytes.
constexpr size_t kMaxVecLine = 3 + 3 * 17 + 1;
char* put_vec(char* p, std::string_view tag, Vec3f v) {
  std::memcpy(p, tag.data(), tag.size());
  p += tag.size();
  for (float c : {v.x, v.y, v.z}) {
    *p++ = ' ';
    p = std::to_chars(p, p + 16, c).ptr;
  }
  *p++ = '\n';
  return p;
}

// "f a//a b//b c//c\n" (or "f a b c\n"); at most kMaxFaceLine bytes.
constexpr size_t kMaxFaceLine = 1 + 3 * (1 + 20 + 2 + 20) + 1;

}  // namespace

void write_obj(const PartList& parts, std::ostream& obj, std::ostream& mtl,
               const std::string& mtl_file_name) {
  UniqueNames used(/*fold_case=*/false);
  std::vector<std::string> materials;
  for (const Part* part : parts) materials.push_back(material_name(part->name, used));

  std::string m = "# segmesh materials: Kd base colour; PBR extension: Pr roughness, Pm metallic\n";
  for (size_t i = 0; i < parts.size(); ++i) {
    const Material& mat = parts[i]->material;
    const std::string kd = format_float(mat.base_color.r) + " " + format_float(mat.base_color.g) +
                           " " + format_float(mat.base_color.b);
    // Blinn-Phong for readers without PBR: metals reflect their own colour, dielectrics ~4 %;
    // Ns from roughness with the usual alpha = roughness^2, Ns = 2 / alpha^2 - 2 mapping.
    const float alpha = std::max(mat.roughness * mat.roughness, 1e-3f);
    const float ns = std::clamp(2.0f / (alpha * alpha) - 2.0f, 0.0f, 1000.0f);
    const std::string ks = mat.metallic >= 0.5f ? kd : "0.04 0.04 0.04";
    m += "\nnewmtl " + materials[i] + "\nKa 0 0 0\nKd " + kd + "\nKs " + ks + "\nNs " +
         format_float(std::round(ns * 10) / 10) + "\nd 1\nillum 2\nPr " + format_float(mat.roughness) +
         "\nPm " + format_float(mat.metallic) + "\n";
  }
  mtl.write(m.data(), static_cast<std::streamsize>(m.size()));

  PieceList pieces;
  std::string head =
      "# SPACE=LPS\n# segmesh: world millimetres, LPS (x = left, y = posterior, z = superior)\n";
  head += "mtllib " + mtl_file_name + "\n";
  uint64_t first = 1, first_normal = 1;  // normals are numbered apart: not every part has them
  for (size_t i = 0; i < parts.size(); ++i) {
    const Part& part = *parts[i];
    const TriMesh& mesh = part.mesh;
    const Placement placement(part);
    head += "\n# segmesh part label=" + std::to_string(part.label) +
            " component=" + std::to_string(part.component) + " role=" +
            std::string(role_name(part.role)) + " voxels=" + std::to_string(part.voxels) +
            " visible=" + (part.visible ? "1" : "0") + "\n";
    head += "o " + one_line(part.name) + "\nusemtl " + materials[i] + "\n";
    pieces.text(std::move(head));
    head.clear();
    constexpr size_t per_piece = kPieceBytes / kMaxVecLine;
    pieces.items(mesh.vertex_count(), per_piece,
                 [&mesh, placement](size_t begin, size_t end, ChunkBuffer& buffer) {
                   char* p = buffer.room((end - begin) * kMaxVecLine);
                   for (size_t v = begin; v < end; ++v) p = put_vec(p, "v", placement.point(mesh.positions[v]));
                   buffer.commit(p);
                   return buffer.view();
                 });
    pieces.items(mesh.normals.size(), per_piece,
                 [&mesh, placement](size_t begin, size_t end, ChunkBuffer& buffer) {
                   char* p = buffer.room((end - begin) * kMaxVecLine);
                   for (size_t v = begin; v < end; ++v) p = put_vec(p, "vn", placement.normal(mesh.normals[v]));
                   buffer.commit(p);
                   return buffer.view();
                 });
    const bool normals = !mesh.normals.empty();
    pieces.items(mesh.triangle_count(), kPieceBytes / kMaxFaceLine,
                 [&mesh, placement, normals, first, first_normal](size_t begin, size_t end,
                                                                   ChunkBuffer& buffer) {
                   char* p = buffer.room((end - begin) * kMaxFaceLine);
                   for (size_t t = begin; t < end; ++t) {
                     const std::array<uint32_t, 3> c = placement.corners(mesh, t);
                     *p++ = 'f';
                     for (uint32_t index : c) {
                       *p++ = ' ';
                       char* number = p;
                       p = std::to_chars(p, p + 20, first + index).ptr;
                       if (normals) {
                         *p++ = '/';
                         *p++ = '/';
                         if (first_normal == first) {  // the same number again
                           const size_t digits = static_cast<size_t>(p - 2 - number);
                           std::memcpy(p, number, digits);
                           p += digits;
                         } else {
                           p = std::to_chars(p, p + 20, first_normal + index).ptr;
                         }
                       }
                     }
                     *p++ = '\n';
                   }
                   buffer.commit(p);
                   return buffer.view();
                 });
    first += mesh.vertex_count();
    first_normal += mesh.normals.size();
  }
  pieces.text(std::move(head));
  pieces.write(obj);
}

}  // namespace segmesh
