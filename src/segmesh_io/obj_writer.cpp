#include "segmesh_io/obj_writer.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

namespace segmesh {

using namespace mesh_io;

namespace {

std::string material_name(const std::string& part_name, std::set<std::string>& used) {
  std::string base = one_line(part_name);
  for (char& c : base) {
    if (std::isspace(static_cast<unsigned char>(c))) c = '_';
  }
  if (base.empty()) base = "part";
  std::string name = base;
  for (int n = 2; used.count(name); ++n) name = base + "_" + std::to_string(n);
  used.insert(name);
  return name;
}

void append_vec(std::string& buf, const char* tag, Vec3f v) {
  buf += tag;
  buf += ' ';
  buf += format_float(v.x);
  buf += ' ';
  buf += format_float(v.y);
  buf += ' ';
  buf += format_float(v.z);
  buf += '\n';
}

}  // namespace

void write_obj(const PartList& parts, std::ostream& obj, std::ostream& mtl,
               const std::string& mtl_file_name) {
  std::set<std::string> used;
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

  BlockWriter writer(obj);
  std::string& buf = writer.buffer();
  buf += "# SPACE=LPS\n# segmesh: world millimetres, LPS (x = left, y = posterior, z = superior)\n";
  buf += "mtllib " + mtl_file_name + "\n";
  uint64_t first = 1, first_normal = 1;  // normals are numbered apart: not every part has them
  for (size_t i = 0; i < parts.size(); ++i) {
    const Part& part = *parts[i];
    const PlacedMesh placed(part);
    const TriMesh& mesh = placed.mesh();
    buf += "\n# segmesh part label=" + std::to_string(part.label) +
           " component=" + std::to_string(part.component) + " role=" +
           std::string(role_name(part.role)) + " voxels=" + std::to_string(part.voxels) +
           " visible=" + (part.visible ? "1" : "0") + "\n";
    buf += "o " + one_line(part.name) + "\nusemtl " + materials[i] + "\n";
    for (const Vec3f& p : mesh.positions) {
      append_vec(buf, "v", p);
      writer.maybe_flush();
    }
    for (const Vec3f& n : mesh.normals) {
      append_vec(buf, "vn", n);
      writer.maybe_flush();
    }
    const bool normals = !mesh.normals.empty();
    for (size_t t = 0; t < mesh.indices.size(); t += 3) {
      buf += 'f';
      for (int c = 0; c < 3; ++c) {
        buf += ' ';
        buf += std::to_string(first + mesh.indices[t + c]);
        if (normals) {
          buf += "//";
          buf += std::to_string(first_normal + mesh.indices[t + c]);
        }
      }
      buf += '\n';
      writer.maybe_flush();
    }
    first += mesh.vertex_count();
    first_normal += mesh.normals.size();
  }
  writer.flush();
}

}  // namespace segmesh
