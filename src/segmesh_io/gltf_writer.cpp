#include "segmesh_io/gltf_writer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace segmesh {

using namespace mesh_io;
using Json = nlohmann::ordered_json;

namespace {

constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

class GlbBuilder {
 public:
  // Appends raw bytes as a new bufferView and an accessor over it; returns the accessor index.
  size_t add_accessor(const void* data, size_t bytes, size_t count, int component_type,
                      const char* type, int target, bool normalized = false) {
    while (bin_.size() % 4) bin_.push_back('\0');
    const size_t offset = bin_.size();
    bin_.append(static_cast<const char*>(data), bytes);
    views_.push_back(Json{{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes}, {"target", target}});
    Json accessor{{"bufferView", views_.size() - 1}, {"componentType", component_type}};
    if (normalized) accessor["normalized"] = true;
    accessor["count"] = count;
    accessor["type"] = type;
    accessors_.push_back(std::move(accessor));
    return accessors_.size() - 1;
  }
  Json& accessor(size_t i) { return accessors_[i]; }
  Json& views() { return views_; }
  Json& accessors() { return accessors_; }
  std::string& bin() { return bin_; }

 private:
  std::string bin_;
  Json views_ = Json::array();
  Json accessors_ = Json::array();
};

// Unit normals the validator accepts: re-normalised in double; a zero or broken normal is replaced
// by the area-weighted normal of the vertex's triangles (or +Z when those are degenerate too).
std::vector<Vec3f> unit_normals(const TriMesh& m) {
  std::vector<Vec3f> out(m.normals.size());
  std::vector<size_t> broken;
  for (size_t v = 0; v < m.normals.size(); ++v) {
    const Vec3d n = to_double(m.normals[v]);
    const double len = norm(n);
    if (std::isfinite(len) && len > 1e-12) out[v] = to_float((1.0 / len) * n);
    else broken.push_back(v);
  }
  if (broken.empty()) return out;
  std::vector<Vec3d> sum(m.positions.size());
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const Vec3d a = to_double(m.positions[m.indices[t]]);
    const Vec3d n = cross(to_double(m.positions[m.indices[t + 1]]) - a,
                          to_double(m.positions[m.indices[t + 2]]) - a);
    for (int c = 0; c < 3; ++c) sum[m.indices[t + c]] = sum[m.indices[t + c]] + n;
  }
  for (size_t v : broken) {
    const double len = norm(sum[v]);
    out[v] = len > 0 && std::isfinite(len) ? to_float((1.0 / len) * sum[v]) : Vec3f{0, 0, 1};
  }
  return out;
}

Json matrix_json(const Transform& t) {
  Json m = Json::array();
  for (double v : t) m.push_back(v);
  return m;
}

}  // namespace

void write_glb(const PartList& parts, std::ostream& out) {
  GlbBuilder b;
  Json nodes = Json::array(), meshes = Json::array(), materials = Json::array();
  Json root{{"name", kGltfRootName}, {"matrix", matrix_json(kGltfRootMatrix)}};
  Json children = Json::array();
  nodes.push_back(nullptr);  // the root goes first; filled in once its children are known

  for (const Part* part_ptr : parts) {
    const Part& part = *part_ptr;
    const TriMesh& m = part.mesh;
    if (m.vertex_count() > std::numeric_limits<uint32_t>::max() - 1) {
      throw Error("glTF part '" + part.name + "' has too many vertices for uint32 indices");
    }
    Json attributes = Json::object();

    Vec3f lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
             std::numeric_limits<float>::max()};
    Vec3f hi{-lo.x, -lo.y, -lo.z};
    for (const Vec3f& p : m.positions) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    const size_t position = b.add_accessor(m.positions.data(), m.positions.size() * 12,
                                           m.positions.size(), kFloat, "VEC3", kArrayBuffer);
    // float -> double is exact, so the validator's min/max comparison against the data holds.
    b.accessor(position)["min"] = {double(lo.x), double(lo.y), double(lo.z)};
    b.accessor(position)["max"] = {double(hi.x), double(hi.y), double(hi.z)};
    attributes["POSITION"] = position;
    if (!m.normals.empty()) {
      const std::vector<Vec3f> normals = unit_normals(m);
      attributes["NORMAL"] = b.add_accessor(normals.data(), normals.size() * 12, normals.size(),
                                            kFloat, "VEC3", kArrayBuffer);
    }
    if (!m.colors.empty()) {
      attributes["COLOR_0"] = b.add_accessor(m.colors.data(), m.colors.size() * 4, m.colors.size(),
                                             kUnsignedByte, "VEC4", kArrayBuffer, true);
    }
    static_assert(std::endian::native == std::endian::little, "GLB data are little-endian");
    const size_t indices = b.add_accessor(m.indices.data(), m.indices.size() * 4, m.indices.size(),
                                          kUnsignedInt, "SCALAR", kElementArrayBuffer);

    const Material& mat = part.material;
    const auto unit = [](float v) { return tidy(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f)); };
    materials.push_back(Json{
        {"name", part.name},
        {"pbrMetallicRoughness",
         {{"baseColorFactor", {unit(mat.base_color.r), unit(mat.base_color.g), unit(mat.base_color.b), 1.0}},
          {"metallicFactor", unit(mat.metallic)},
          {"roughnessFactor", unit(mat.roughness)}}}});
    meshes.push_back(Json{
        {"name", part.name},
        {"primitives",
         {{{"attributes", attributes}, {"indices", indices}, {"material", materials.size() - 1},
           {"mode", 4}}}}});
    Json node{{"name", part.name}, {"mesh", meshes.size() - 1}};
    if (!is_identity(part.transform)) node["matrix"] = matrix_json(part.transform);
    node["extras"] = Json{{"label", part.label},
                          {"component", part.component},
                          {"role", role_name(part.role)},
                          {"voxels", part.voxels},
                          {"voxel_volume_mm3", part.voxel_volume_mm3},
                          {"visible", part.visible}};
    children.push_back(nodes.size());
    nodes.push_back(std::move(node));
  }
  if (!children.empty()) root["children"] = children;
  nodes[0] = std::move(root);

  Json gltf;
  gltf["asset"] = Json{
      {"version", "2.0"},
      {"generator", "segmesh"},
      {"extras",
       {{"units", "mm"},
        {"space", "LPS"},
        {"root_transform",
         "node segmesh_scene maps LPS millimetres to glTF metres: gltf = 0.001 * (x, z, -y) "
         "(x Left, +Y Superior, +Z Anterior)"}}}};
  gltf["scene"] = 0;
  gltf["scenes"] = Json::array({Json{{"name", "segmesh"}, {"nodes", {0}}}});
  gltf["nodes"] = std::move(nodes);
  if (!meshes.empty()) {
    gltf["meshes"] = std::move(meshes);
    gltf["materials"] = std::move(materials);
    gltf["accessors"] = std::move(b.accessors());
    gltf["bufferViews"] = std::move(b.views());
  }
  std::string& bin = b.bin();
  while (bin.size() % 4) bin.push_back('\0');
  if (!bin.empty()) gltf["buffers"] = Json::array({Json{{"byteLength", bin.size()}}});

  // Names may come from Latin-1 file headers; invalid UTF-8 becomes U+FFFD instead of a throw.
  std::string json = gltf.dump(-1, ' ', false, Json::error_handler_t::replace);
  while (json.size() % 4) json.push_back(' ');
  const uint64_t total = 12 + 8 + json.size() + (bin.empty() ? 0 : 8 + bin.size());
  if (total > std::numeric_limits<uint32_t>::max()) {
    throw Error("the scene is too large for one GLB file (" + std::to_string(total) +
                " bytes, the format's limit is 4 GiB); write fewer parts per file or use PLY");
  }
  std::string head;
  append_le<uint32_t>(head, 0x46546C67);  // "glTF"
  append_le<uint32_t>(head, 2);
  append_le<uint32_t>(head, static_cast<uint32_t>(total));
  append_le<uint32_t>(head, static_cast<uint32_t>(json.size()));
  append_le<uint32_t>(head, 0x4E4F534A);  // "JSON"
  out.write(head.data(), static_cast<std::streamsize>(head.size()));
  out.write(json.data(), static_cast<std::streamsize>(json.size()));
  if (!bin.empty()) {
    std::string chunk;
    append_le<uint32_t>(chunk, static_cast<uint32_t>(bin.size()));
    append_le<uint32_t>(chunk, 0x004E4942);  // "BIN\0"
    out.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    out.write(bin.data(), static_cast<std::streamsize>(bin.size()));
  }
}

}  // namespace segmesh
