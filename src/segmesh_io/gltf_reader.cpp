#include "segmesh_io/gltf_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <type_traits>
#include <nlohmann/json.hpp>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/gltf_writer.hpp"

namespace segmesh {

using namespace mesh_io;
using Json = nlohmann::json;

namespace {

constexpr int kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123,
              kUnsignedInt = 5125, kFloat = 5126;

size_t component_size(int type) {
  switch (type) {
    case kByte: case kUnsignedByte: return 1;
    case kShort: case kUnsignedShort: return 2;
    case kUnsignedInt: case kFloat: return 4;
    default: return 0;
  }
}

size_t component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  if (type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

class GlbReader {
 public:
  GlbReader(std::string_view bytes, const std::filesystem::path& file) : file_(file) {
    parse_container(bytes);
  }

  Scene read() {
    if (const Json* required = member(doc_, "extensionsRequired"); required && required->is_array()) {
      for (const Json& name : *required) {
        if (name == "KHR_mesh_quantization") continue;  // read_vec3 reads integer attributes
        error("uses the required extension " + name.dump() +
              ", which segmesh cannot read; export it without compression or extensions");
      }
    }
    Scene scene;
    const Json& nodes = array_member(doc_, "nodes");
    std::vector<int> roots;
    const Json* scenes = member(doc_, "scenes");
    if (scenes && scenes->is_array() && !scenes->empty()) {
      const size_t s = member(doc_, "scene") ? index(doc_, "scene", scenes->size(), "scene") : 0;
      const Json& sc = (*scenes)[s];
      if (const Json* list = member(sc, "nodes")) {
        for (size_t i = 0; i < list->size(); ++i) roots.push_back(int(as_index((*list)[i], nodes.size(), "scene node")));
      }
    } else {
      // No scene: every node that is nobody's child is a root.
      std::vector<bool> is_child(nodes.size(), false);
      for (const Json& n : nodes) {
        if (const Json* c = member(n, "children")) {
          for (const Json& i : *c) is_child[as_index(i, nodes.size(), "child node")] = true;
        }
      }
      for (size_t i = 0; i < nodes.size(); ++i) {
        if (!is_child[i]) roots.push_back(int(i));
      }
    }
    visited_.assign(nodes.size(), false);
    for (int r : roots) visit(nodes, r, kGltfToLps, scene, 0);
    return scene;
  }

 private:
  struct View {
    size_t offset = 0, length = 0, stride = 0;
  };

  [[noreturn]] void error(const std::string& what) const { fail(file_, what); }

  void parse_container(std::string_view bytes) {
    if (bytes.size() < 20) {
      if (bytes.starts_with("glTF")) error("GLB file is truncated (" + std::to_string(bytes.size()) + " bytes)");
      error("not a binary glTF (.glb) file");
    }
    if (load_le<uint32_t>(bytes.data()) != 0x46546C67) {
      if (bytes.find_first_not_of(" \t\r\n") != std::string_view::npos &&
          bytes[bytes.find_first_not_of(" \t\r\n")] == '{') {
        error("is a text glTF file; segmesh reads binary glTF (.glb) only");
      }
      error("not a binary glTF (.glb) file (no 'glTF' magic)");
    }
    const uint32_t version = load_le<uint32_t>(bytes.data() + 4);
    if (version != 2) error("GLB version " + std::to_string(version) + " is not supported (only 2)");
    const uint32_t length = load_le<uint32_t>(bytes.data() + 8);
    if (length > bytes.size()) {
      error("GLB header says " + std::to_string(length) + " bytes but the file has " +
            std::to_string(bytes.size()) + "; it is truncated");
    }
    bytes = bytes.substr(0, length);
    size_t pos = 12;
    std::string_view json;
    bool have_bin = false;
    for (int chunk = 0; pos < bytes.size(); ++chunk) {
      if (bytes.size() - pos < 8) error("GLB chunk header is truncated");
      const uint32_t chunk_length = load_le<uint32_t>(bytes.data() + pos);
      const uint32_t chunk_type = load_le<uint32_t>(bytes.data() + pos + 4);
      pos += 8;
      if (chunk_length > bytes.size() - pos) {
        error("GLB chunk " + std::to_string(chunk) + " claims " + std::to_string(chunk_length) +
              " bytes but only " + std::to_string(bytes.size() - pos) + " remain; the file is truncated");
      }
      const std::string_view data = bytes.substr(pos, chunk_length);
      pos += chunk_length;
      if (chunk == 0) {
        if (chunk_type != 0x4E4F534A) error("GLB does not start with a JSON chunk");
        json = data;
      } else if (chunk_type == 0x004E4942 && !have_bin) {
        bin_ = data;
        have_bin = true;
      }
    }
    if (json.empty()) error("GLB has no JSON chunk");
    try {
      doc_ = Json::parse(json.begin(), json.end());
    } catch (const Json::exception& e) {
      error(std::string("GLB JSON chunk is not valid JSON (") + e.what() + ")");
    }
    if (!doc_.is_object()) error("GLB JSON chunk is not a JSON object");
    const Json& asset = object_member(doc_, "asset");
    const Json* version_text = member(asset, "version");
    if (!version_text || !version_text->is_string() || !version_text->get<std::string>().starts_with("2.")) {
      error("is not glTF 2.x (asset.version)");
    }
    if (const Json* buffers = member(doc_, "buffers")) {
      if (!buffers->is_array()) error("glTF 'buffers' is not an array");
      for (size_t i = 0; i < buffers->size(); ++i) {
        const Json& b = (*buffers)[i];
        if (!b.is_object()) error("glTF buffer " + std::to_string(i) + " is not an object");
        if (member(b, "uri") || i > 0 || !have_bin) {
          error("glTF buffer " + std::to_string(i) +
                " is not stored in the GLB's BIN chunk; external and data: URI buffers are not supported");
        }
        const size_t length = size_member(b, "byteLength");
        if (length > bin_.size()) {
          error("glTF buffer 0 claims " + std::to_string(length) + " bytes but the BIN chunk has " +
                std::to_string(bin_.size()));
        }
        bin_ = bin_.substr(0, length);
      }
    }
  }

  // JSON access that turns every shape mismatch into an Error instead of a JSON exception.
  static const Json* member(const Json& obj, const char* key) {
    if (!obj.is_object()) return nullptr;
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }
  const Json& object_member(const Json& obj, const char* key) const {
    const Json* m = member(obj, key);
    if (!m || !m->is_object()) error(std::string("glTF '") + key + "' is missing or not an object");
    return *m;
  }
  const Json& array_member(const Json& obj, const char* key) const {
    static const Json empty = Json::array();
    const Json* m = member(obj, key);
    if (!m) return empty;
    if (!m->is_array()) error(std::string("glTF '") + key + "' is not an array");
    return *m;
  }
  size_t as_size(const Json& v, const std::string& what) const {
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0)) {
      error("glTF " + what + " is not a non-negative integer");
    }
    const uint64_t n = v.get<uint64_t>();
    if (n > (uint64_t{1} << 40)) error("glTF " + what + " is implausibly large (" + std::to_string(n) + ")");
    return static_cast<size_t>(n);
  }
  size_t size_member(const Json& obj, const char* key, std::optional<size_t> fallback = std::nullopt) const {
    const Json* m = member(obj, key);
    if (!m) {
      if (fallback) return *fallback;
      error(std::string("glTF '") + key + "' is missing");
    }
    return as_size(*m, std::string("'") + key + "'");
  }
  size_t as_index(const Json& v, size_t limit, const std::string& what) const {
    const size_t i = as_size(v, what + " index");
    if (i >= limit) {
      error("glTF " + what + " index " + std::to_string(i) + " is out of range (" + std::to_string(limit) + " defined)");
    }
    return i;
  }
  size_t index(const Json& obj, const char* key, size_t limit, const std::string& what) const {
    const Json* m = member(obj, key);
    if (!m) error(std::string("glTF '") + key + "' is missing");
    return as_index(*m, limit, what);
  }
  std::vector<double> numbers(const Json& v, size_t n, const std::string& what) const {
    if (!v.is_array() || v.size() != n) error("glTF " + what + " is not an array of " + std::to_string(n) + " numbers");
    std::vector<double> out;
    for (const Json& x : v) {
      if (!x.is_number()) error("glTF " + what + " holds a non-number");
      out.push_back(x.get<double>());
    }
    return out;
  }

  View view(size_t i) const {
    const Json& views = array_member(doc_, "bufferViews");
    if (i >= views.size()) error("glTF bufferView index " + std::to_string(i) + " is out of range");
    const Json& v = views[i];
    index(v, "buffer", array_member(doc_, "buffers").size(), "buffer");
    View out;
    out.offset = size_member(v, "byteOffset", 0);
    out.length = size_member(v, "byteLength");
    out.stride = size_member(v, "byteStride", 0);
    if (out.offset > bin_.size() || out.length > bin_.size() - out.offset) {
      error("glTF bufferView " + std::to_string(i) + " (offset " + std::to_string(out.offset) + ", " +
            std::to_string(out.length) + " bytes) lies outside its " + std::to_string(bin_.size()) + "-byte buffer");
    }
    return out;
  }

  // Locates accessor `i`, checks its type and that all `count` elements lie inside its view, and
  // returns a pointer to element 0 plus the stride. Nothing is allocated before this passes.
  struct Located {
    const char* data = nullptr;
    size_t count = 0, stride = 0;
    int component_type = 0;
    size_t components = 0;
    bool normalized = false;
  };
  Located locate(size_t i, const char* what) const {
    const Json& accessors = array_member(doc_, "accessors");
    if (i >= accessors.size()) error(std::string("glTF ") + what + " accessor index is out of range");
    const Json& a = accessors[i];
    if (member(a, "sparse")) error(std::string("glTF sparse accessors are not supported (") + what + ")");
    if (!member(a, "bufferView")) error(std::string("glTF ") + what + " accessor has no bufferView");
    Located loc;
    const Json* ct = member(a, "componentType");
    if (!ct || !ct->is_number_integer()) error(std::string("glTF ") + what + " accessor has no componentType");
    loc.component_type = ct->get<int>();
    const Json* type = member(a, "type");
    if (!type || !type->is_string()) error(std::string("glTF ") + what + " accessor has no type");
    loc.components = component_count(type->get<std::string>());
    const size_t csize = component_size(loc.component_type);
    if (!csize || !loc.components) error(std::string("glTF ") + what + " accessor has an unknown type");
    if (const Json* n = member(a, "normalized")) loc.normalized = n->is_boolean() && n->get<bool>();
    loc.count = size_member(a, "count");
    const View v = view(index(a, "bufferView", array_member(doc_, "bufferViews").size(), "bufferView"));
    const size_t offset = size_member(a, "byteOffset", 0);
    const size_t element = csize * loc.components;
    loc.stride = v.stride ? v.stride : element;
    if (loc.stride < element) error(std::string("glTF ") + what + " accessor's byteStride is smaller than its element");
    if (loc.count > 0 && (offset > v.length || v.length - offset < element ||
                          (loc.count - 1) > (v.length - offset - element) / loc.stride)) {
      error(std::string("glTF ") + what + " accessor claims " + std::to_string(loc.count) +
            " elements, more than its bufferView holds; the file is corrupt");
    }
    loc.data = bin_.data() + v.offset + offset;
    return loc;
  }

  std::vector<Vec3f> read_vec3(size_t accessor, const char* what) const {
    const Located loc = locate(accessor, what);
    if (loc.component_type == kUnsignedInt || loc.components != 3) {
      error(std::string("glTF ") + what + " must be VEC3 of float or (KHR_mesh_quantization) 8- or 16-bit integers");
    }
    // An integer component as KHR_mesh_quantization reads it: normalised values scaled to [0, 1]
    // or [-1, 1] (signed clamped at -1), others as they are.
    const int type = loc.component_type;
    const bool normalized = loc.normalized;
    const size_t csize = component_size(type);
    const auto component = [type, normalized](const char* p) -> float {
      switch (type) {
        case kByte: { const float v = static_cast<int8_t>(*p); return normalized ? std::max(v / 127.0f, -1.0f) : v; }
        case kUnsignedByte: { const float v = static_cast<uint8_t>(*p); return normalized ? v / 255.0f : v; }
        case kShort: { const float v = load_le<int16_t>(p); return normalized ? std::max(v / 32767.0f, -1.0f) : v; }
        case kUnsignedShort: { const float v = load_le<uint16_t>(p); return normalized ? v / 65535.0f : v; }
        default: return load_le<float>(p);
      }
    };
    std::vector<Vec3f> out(loc.count);
    for (size_t k = 0; k < loc.count; ++k) {
      const char* p = loc.data + k * loc.stride;
      out[k] = {component(p), component(p + csize), component(p + 2 * csize)};
    }
    return out;
  }

  std::vector<Rgba8> read_colors(size_t accessor, size_t expected) const {
    const Located loc = locate(accessor, "COLOR_0");
    const bool ok_type = loc.component_type == kFloat ||
                         (loc.normalized && (loc.component_type == kUnsignedByte || loc.component_type == kUnsignedShort));
    if (!ok_type || (loc.components != 3 && loc.components != 4)) {
      error("glTF COLOR_0 must be float or normalised ubyte/ushort, VEC3 or VEC4");
    }
    if (loc.count != expected) error("glTF COLOR_0 count differs from POSITION count");
    std::vector<Rgba8> out(loc.count);
    const size_t csize = component_size(loc.component_type);
    for (size_t k = 0; k < loc.count; ++k) {
      const char* p = loc.data + k * loc.stride;
      Rgba8 c{255, 255, 255, 255};
      for (size_t j = 0; j < loc.components; ++j) {
        const char* q = p + j * csize;
        if (loc.component_type == kUnsignedByte) c[j] = static_cast<uint8_t>(*q);
        else if (loc.component_type == kUnsignedShort) c[j] = static_cast<uint8_t>((load_le<uint16_t>(q) * 255u + 32767u) / 65535u);
        else c[j] = to_unorm8(load_le<float>(q));
      }
      out[k] = c;
    }
    return out;
  }

  std::vector<uint32_t> read_indices(size_t accessor, size_t vertex_count) const {
    const Located loc = locate(accessor, "indices");
    if (loc.components != 1 || (loc.component_type != kUnsignedByte && loc.component_type != kUnsignedShort &&
                                loc.component_type != kUnsignedInt)) {
      error("glTF indices must be unsigned byte, short or int scalars");
    }
    if (loc.count % 3) error("glTF triangle index count " + std::to_string(loc.count) + " is not a multiple of 3");
    std::vector<uint32_t> out(loc.count);
    for (size_t k = 0; k < loc.count; ++k) {
      const char* p = loc.data + k * loc.stride;
      const uint32_t i = loc.component_type == kUnsignedByte    ? static_cast<uint8_t>(*p)
                         : loc.component_type == kUnsignedShort ? load_le<uint16_t>(p)
                                                                : load_le<uint32_t>(p);
      if (i >= vertex_count) {
        error("glTF index " + std::to_string(i) + " is out of range (" + std::to_string(vertex_count) + " vertices)");
      }
      out[k] = i;
    }
    return out;
  }

  Transform local_matrix(const Json& node) const {
    if (const Json* m = member(node, "matrix")) {
      const std::vector<double> v = numbers(*m, 16, "node matrix");
      Transform t{};
      std::copy(v.begin(), v.end(), t.begin());
      return t;
    }
    std::vector<double> tr{0, 0, 0}, q{0, 0, 0, 1}, s{1, 1, 1};
    if (const Json* m = member(node, "translation")) tr = numbers(*m, 3, "node translation");
    if (const Json* m = member(node, "rotation")) q = numbers(*m, 4, "node rotation");
    if (const Json* m = member(node, "scale")) s = numbers(*m, 3, "node scale");
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    // Column-major rotation from the unit quaternion (x, y, z, w), columns scaled by s.
    return {(1 - 2 * (y * y + z * z)) * s[0], 2 * (x * y + z * w) * s[0], 2 * (x * z - y * w) * s[0], 0,
            2 * (x * y - z * w) * s[1], (1 - 2 * (x * x + z * z)) * s[1], 2 * (y * z + x * w) * s[1], 0,
            2 * (x * z + y * w) * s[2], 2 * (y * z - x * w) * s[2], (1 - 2 * (x * x + y * y)) * s[2], 0,
            tr[0], tr[1], tr[2], 1};
  }

  void visit(const Json& nodes, int i, const Transform& parent, Scene& scene, int depth) {
    if (depth > 256) error("glTF node hierarchy is too deep");
    if (visited_[i]) error("glTF node " + std::to_string(i) + " appears twice in the hierarchy");
    visited_[i] = true;
    const Json& node = nodes[i];
    if (!node.is_object()) error("glTF node " + std::to_string(i) + " is not an object");
    const Transform world = multiply(parent, local_matrix(node));
    if (member(node, "mesh")) add_part(node, world, scene);
    if (const Json* c = member(node, "children")) {
      if (!c->is_array()) error("glTF node children is not an array");
      for (const Json& child : *c) visit(nodes, int(as_index(child, nodes.size(), "child node")), world, scene, depth + 1);
    }
  }

  void add_part(const Json& node, const Transform& world, Scene& scene) {
    const Json& meshes = array_member(doc_, "meshes");
    const Json& mesh = meshes[index(node, "mesh", meshes.size(), "mesh")];
    Part part;
    part.material = neutral_material();
    if (const Json* n = member(node, "name"); n && n->is_string()) part.name = n->get<std::string>();
    if (const Json* n = member(mesh, "name"); part.name.empty() && n && n->is_string()) part.name = n->get<std::string>();
    if (part.name.empty()) part.name = "part_" + std::to_string(scene.parts.size() + 1);

    bool all_normals = true, all_colors = true;
    const Json& primitives = array_member(mesh, "primitives");
    TriMesh& m = part.mesh;
    for (size_t p = 0; p < primitives.size(); ++p) {
      const Json& prim = primitives[p];
      if (const Json* mode = member(prim, "mode"); mode && !(mode->is_number_integer() && mode->get<int>() == 4)) {
        error("glTF mesh '" + part.name + "' has a primitive of mode " + mode->dump() +
              "; only triangles (mode 4) are supported");
      }
      const Json& attributes = object_member(prim, "attributes");
      const size_t first = m.positions.size();
      std::vector<Vec3f> positions = read_vec3(index(attributes, "POSITION", SIZE_MAX, "POSITION accessor"), "POSITION");
      if (first + positions.size() > std::numeric_limits<uint32_t>::max()) error("glTF mesh has too many vertices");
      std::vector<uint32_t> indices;
      if (member(prim, "indices")) {
        indices = read_indices(index(prim, "indices", SIZE_MAX, "indices accessor"), positions.size());
      } else {
        if (positions.size() % 3) error("glTF non-indexed primitive has a vertex count that is not a multiple of 3");
        indices.resize(positions.size());
        for (size_t k = 0; k < indices.size(); ++k) indices[k] = static_cast<uint32_t>(k);
      }
      m.positions.insert(m.positions.end(), positions.begin(), positions.end());
      for (uint32_t i : indices) m.indices.push_back(static_cast<uint32_t>(first + i));
      if (member(attributes, "NORMAL") && all_normals) {
        std::vector<Vec3f> normals = read_vec3(index(attributes, "NORMAL", SIZE_MAX, "NORMAL accessor"), "NORMAL");
        if (normals.size() != positions.size()) error("glTF NORMAL count differs from POSITION count");
        m.normals.insert(m.normals.end(), normals.begin(), normals.end());
      } else {
        all_normals = false;
      }
      if (member(attributes, "COLOR_0") && all_colors) {
        std::vector<Rgba8> colors = read_colors(index(attributes, "COLOR_0", SIZE_MAX, "COLOR_0 accessor"), positions.size());
        m.colors.insert(m.colors.end(), colors.begin(), colors.end());
      } else {
        all_colors = false;
      }
      if (p == 0 && member(prim, "material")) read_material(index(prim, "material", array_member(doc_, "materials").size(), "material"), part.material);
    }
    if (!all_normals) m.normals.clear();
    if (!all_colors) m.colors.clear();
    read_extras(node, part);

    // For a segmesh file world = kGltfToLps * root * node = node exactly (the root's factors are
    // 1000 * 0.001 = 1 and zeros), so node matrices come back bit for bit.
    if (is_rigid(world)) {
      part.transform = world;
    } else {
      for (Vec3f& v : m.positions) v = to_float(transform_point(world, to_double(v)));
      for (Vec3f& n : m.normals) n = to_float(transform_normal(world, to_double(n)));
      if (linear_determinant(world) < 0) {
        for (size_t t = 0; t + 2 < m.indices.size(); t += 3) std::swap(m.indices[t + 1], m.indices[t + 2]);
      }
    }
    scene.parts.push_back(std::move(part));
  }

  void read_material(size_t i, Material& out) const {
    const Json& mat = array_member(doc_, "materials")[i];
    out = {Rgb{1, 1, 1}, 1.0f, 1.0f};  // glTF's defaults for an unset factor
    const Json* pbr = member(mat, "pbrMetallicRoughness");
    if (!pbr) return;
    if (const Json* c = member(*pbr, "baseColorFactor")) {
      const std::vector<double> v = numbers(*c, 4, "baseColorFactor");
      out.base_color = {float(v[0]), float(v[1]), float(v[2])};
    }
    if (const Json* v = member(*pbr, "metallicFactor"); v && v->is_number()) out.metallic = v->get<float>();
    if (const Json* v = member(*pbr, "roughnessFactor"); v && v->is_number()) out.roughness = v->get<float>();
  }

  static void read_extras(const Json& node, Part& part) {
    const Json* extras = member(node, "extras");
    if (!extras || !extras->is_object()) return;
    const auto integer = [&](const char* key, auto& out) {
      if (const Json* v = member(*extras, key); v && v->is_number_integer()) {
        out = v->get<std::remove_reference_t<decltype(out)>>();
      }
    };
    integer("label", part.label);
    integer("component", part.component);
    integer("voxels", part.voxels);
    if (const Json* v = member(*extras, "voxel_volume_mm3"); v && v->is_number()) part.voxel_volume_mm3 = v->get<double>();
    if (const Json* v = member(*extras, "visible"); v && v->is_boolean()) part.visible = v->get<bool>();
    if (const Json* v = member(*extras, "role"); v && v->is_string()) {
      part.role = parse_role(v->get<std::string>()).value_or(Role::other);
    }
  }

  const std::filesystem::path& file_;
  Json doc_;
  std::string_view bin_;
  std::vector<bool> visited_;
};

}  // namespace

Scene read_glb(std::string_view bytes, const std::filesystem::path& file) {
  return GlbReader(bytes, file).read();
}

}  // namespace segmesh
