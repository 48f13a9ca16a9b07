#include "segmesh_io/detail/glb_document.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"
#include "segmesh_io/gltf_writer.hpp"

namespace segmesh::mesh_io {

using Json = nlohmann::ordered_json;

namespace {

constexpr int kFloat = 5126, kUnsignedByte = 5121, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// The binary chunk is described first (views and accessors with their offsets) and streamed
// afterwards straight from the meshes, so the file is never assembled in memory.
struct BinSource {
  enum class Kind { bytes, normals } kind;
  const void* data;        // Kind::bytes: the array written as it is
  const TriMesh* mesh;     // Kind::normals: whose normals are written unit length
  size_t offset, bytes;    // place in the binary chunk
};

class GlbBuilder {
 public:
  // Reserves `bytes` as a new bufferView and an accessor over it; returns the accessor index.
  size_t add_accessor(BinSource source, size_t count, int component_type, const char* type,
                      int target, bool normalized = false) {
    size_ = (size_ + 3) / 4 * 4;
    source.offset = size_;
    size_ += source.bytes;
    views_.push_back(Json{{"buffer", 0}, {"byteOffset", source.offset}, {"byteLength", source.bytes}, {"target", target}});
    sources_.push_back(source);
    Json accessor{{"bufferView", views_.size() - 1}, {"componentType", component_type}};
    if (normalized) accessor["normalized"] = true;
    accessor["count"] = count;
    accessor["type"] = type;
    accessors_.push_back(std::move(accessor));
    return accessors_.size() - 1;
  }
  size_t add_bytes(const void* data, size_t bytes, size_t count, int component_type,
                   const char* type, int target, bool normalized = false) {
    return add_accessor(BinSource{BinSource::Kind::bytes, data, nullptr, 0, bytes}, count,
                        component_type, type, target, normalized);
  }
  Json& accessor(size_t i) { return accessors_[i]; }
  Json& views() { return views_; }
  Json& accessors() { return accessors_; }
  const std::vector<BinSource>& sources() const { return sources_; }
  // The binary chunk's length, padded to 4 bytes.
  size_t bin_size() const { return (size_ + 3) / 4 * 4; }

 private:
  size_t size_ = 0;
  std::vector<BinSource> sources_;
  Json views_ = Json::array();
  Json accessors_ = Json::array();
};

// Unit normals the validator accepts: re-normalised in double; a zero or broken normal is replaced
// by the area-weighted normal of the vertex's triangles (or +Z when those are degenerate too).
// Computed piece by piece as the file is written; the triangle sums behind the replacement are
// computed once per mesh, only when a broken normal turns up.
class UnitNormals {
 public:
  explicit UnitNormals(const TriMesh& mesh) : m_(mesh) {}

  // Normals [begin, end) as little-endian float triples at out.
  void fill(size_t begin, size_t end, char* out) {
    static_assert(std::endian::native == std::endian::little && sizeof(Vec3f) == 12);
    for (size_t v = begin; v < end; ++v) {
      const Vec3d n = to_double(m_.normals[v]);
      const double len = norm(n);
      Vec3f unit;
      if (std::isfinite(len) && len > 1e-12) {
        unit = to_float((1.0 / len) * n);
      } else {
        const std::vector<Vec3d>& sum = sums();
        const double s = norm(sum[v]);
        unit = s > 0 && std::isfinite(s) ? to_float((1.0 / s) * sum[v]) : Vec3f{0, 0, 1};
      }
      std::memcpy(out + 12 * (v - begin), &unit, 12);
    }
  }

 private:
  const std::vector<Vec3d>& sums() {
    std::call_once(once_, [&] {
      sum_.assign(m_.positions.size(), Vec3d{});
      for (size_t t = 0; t < m_.indices.size(); t += 3) {
        const Vec3d a = to_double(m_.positions[m_.indices[t]]);
        const Vec3d n = cross(to_double(m_.positions[m_.indices[t + 1]]) - a,
                              to_double(m_.positions[m_.indices[t + 2]]) - a);
        for (int c = 0; c < 3; ++c) sum_[m_.indices[t + c]] = sum_[m_.indices[t + c]] + n;
      }
    });
    return sum_;
  }

  const TriMesh& m_;
  std::once_flag once_;
  std::vector<Vec3d> sum_;
};

Json matrix_json(const Transform& t) {
  Json m = Json::array();
  for (double v : t) m.push_back(v);
  return m;
}

Json extras_json(const GlbExtras& extras) {
  Json j = Json::object();
  for (const auto& [key, value] : extras) {
    std::visit([&j, &key](const auto& v) { j[key] = v; }, value);
  }
  return j;
}

Json material_json(const GlbMaterial& m) {
  const Material& mat = m.material;
  const auto unit = [](float v) { return tidy(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f)); };
  return Json{{"name", m.name},
              {"pbrMetallicRoughness",
               {{"baseColorFactor", {unit(mat.base_color.r), unit(mat.base_color.g), unit(mat.base_color.b), 1.0}},
                {"metallicFactor", unit(mat.metallic)},
                {"roughnessFactor", unit(mat.roughness)}}}};
}

// The accessors of one mesh's vertices: POSITION with its bounds, NORMAL and COLOR_0 when asked.
Json vertex_attributes(const GlbMesh& mesh, GlbBuilder& b) {
  const TriMesh& m = *mesh.vertices;
  if (m.vertex_count() > std::numeric_limits<uint32_t>::max() - 1) {
    throw Error("glTF mesh '" + mesh.name + "' has too many vertices for uint32 indices");
  }
  Json attributes = Json::object();
  Vec3f lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
           std::numeric_limits<float>::max()};
  Vec3f hi{-lo.x, -lo.y, -lo.z};
  for (const Vec3f& p : m.positions) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  static_assert(sizeof(Vec3f) == 12 && sizeof(Rgba8) == 4, "accessor data are written as they are");
  const size_t position = b.add_bytes(m.positions.data(), m.positions.size() * 12,
                                      m.positions.size(), kFloat, "VEC3", kArrayBuffer);
  // float -> double is exact, so the validator's min/max comparison against the data holds.
  b.accessor(position)["min"] = {double(lo.x), double(lo.y), double(lo.z)};
  b.accessor(position)["max"] = {double(hi.x), double(hi.y), double(hi.z)};
  attributes["POSITION"] = position;
  if (mesh.normals) {
    attributes["NORMAL"] = b.add_accessor(
        BinSource{BinSource::Kind::normals, nullptr, &m, 0, m.normals.size() * 12},
        m.normals.size(), kFloat, "VEC3", kArrayBuffer);
  }
  if (mesh.colors) {
    attributes["COLOR_0"] = b.add_bytes(m.colors.data(), m.colors.size() * 4, m.colors.size(),
                                        kUnsignedByte, "VEC4", kArrayBuffer, true);
  }
  return attributes;
}

// The GLB container: header, JSON chunk and BIN chunk, the binary data streamed from its sources.
void write_container(const Json& gltf, const GlbBuilder& b, std::ostream& out) {
  const size_t bin_size = b.bin_size();
  // Names may come from Latin-1 file headers; invalid UTF-8 becomes U+FFFD instead of a throw.
  std::string json = gltf.dump(-1, ' ', false, Json::error_handler_t::replace);
  while (json.size() % 4) json.push_back(' ');
  const uint64_t total = 12 + 8 + json.size() + (bin_size == 0 ? 0 : 8 + bin_size);
  if (total > std::numeric_limits<uint32_t>::max()) {
    throw Error("the scene is too large for one GLB file (" + std::to_string(total) +
                " bytes, the format's limit is 4 GiB); write fewer parts per file or use PLY");
  }
  std::string head;
  head.reserve(28 + json.size());
  append_le<uint32_t>(head, 0x46546C67);  // "glTF"
  append_le<uint32_t>(head, 2);
  append_le<uint32_t>(head, static_cast<uint32_t>(total));
  append_le<uint32_t>(head, static_cast<uint32_t>(json.size()));
  append_le<uint32_t>(head, 0x4E4F534A);  // "JSON"
  head += json;
  if (bin_size > 0) {
    append_le<uint32_t>(head, static_cast<uint32_t>(bin_size));
    append_le<uint32_t>(head, 0x004E4942);  // "BIN\0"
  }

  PieceList pieces;
  pieces.text(std::move(head));
  std::vector<std::unique_ptr<UnitNormals>> normals;
  size_t written = 0;
  const auto pad_to = [&](size_t offset) {
    if (offset > written) pieces.text(std::string(offset - written, '\0'));
    written = offset;
  };
  for (const BinSource& source : b.sources()) {
    pad_to(source.offset);
    if (source.kind == BinSource::Kind::bytes) {
      pieces.bytes(source.data, source.bytes);
    } else {
      UnitNormals& unit = *normals.emplace_back(std::make_unique<UnitNormals>(*source.mesh));
      pieces.items(source.mesh->normals.size(), kPieceBytes / 12,
                   [&unit](size_t begin, size_t end, ChunkBuffer& buffer) {
                     char* p = buffer.room((end - begin) * 12);
                     unit.fill(begin, end, p);
                     buffer.commit(p + (end - begin) * 12);
                     return buffer.view();
                   });
    }
    written = source.offset + source.bytes;
  }
  pad_to(bin_size);
  pieces.write(out);
}

}  // namespace

void write_glb_scene(const GlbScene& scene, std::ostream& out) {
  GlbBuilder b;
  Json nodes = Json::array(), meshes = Json::array(), materials = Json::array();
  Json root{{"name", kGltfRootName}, {"matrix", matrix_json(kGltfRootMatrix)}};
  Json children = Json::array();
  nodes.push_back(nullptr);  // the root goes first; filled in once its children are known

  for (const GlbMesh& mesh : scene.meshes) {
    if (mesh.primitives.empty()) continue;
    const Json attributes = vertex_attributes(mesh, b);
    Json primitives = Json::array();
    for (const GlbPrimitive& primitive : mesh.primitives) {
      static_assert(std::endian::native == std::endian::little, "GLB data are little-endian");
      const size_t indices =
          b.add_bytes(primitive.indices.data(), primitive.indices.size() * 4,
                      primitive.indices.size(), kUnsignedInt, "SCALAR", kElementArrayBuffer);
      Json p{{"attributes", attributes}, {"indices", indices}, {"material", primitive.material},
             {"mode", 4}};
      if (!primitive.extras.empty()) p["extras"] = extras_json(primitive.extras);
      primitives.push_back(std::move(p));
    }
    meshes.push_back(Json{{"name", mesh.name}, {"primitives", std::move(primitives)}});
    Json node{{"name", mesh.name}, {"mesh", meshes.size() - 1}};
    if (!is_identity(mesh.matrix)) node["matrix"] = matrix_json(mesh.matrix);
    if (!mesh.extras.empty()) node["extras"] = extras_json(mesh.extras);
    children.push_back(nodes.size());
    nodes.push_back(std::move(node));
  }
  if (!children.empty()) root["children"] = children;
  nodes[0] = std::move(root);
  for (const GlbMaterial& m : scene.materials) materials.push_back(material_json(m));

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
  if (b.bin_size() > 0) gltf["buffers"] = Json::array({Json{{"byteLength", b.bin_size()}}});
  write_container(gltf, b, out);
}

}  // namespace segmesh::mesh_io
