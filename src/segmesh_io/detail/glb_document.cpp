#include "segmesh_io/detail/glb_document.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>

#include "segmesh_io/detail/byte_order.hpp"
#include "segmesh_io/detail/json_text.hpp"
#include "segmesh_io/detail/mesh_io_common.hpp"
#include "segmesh_io/detail/piece_writer.hpp"
#include "segmesh_io/gltf_writer.hpp"

namespace segmesh::mesh_io {

namespace {

constexpr int kFloat = 5126, kByte = 5120, kUnsignedByte = 5121, kUnsignedShort = 5123,
              kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

// The binary chunk is described first (views and accessors with their offsets) and streamed
// afterwards straight from the meshes, so the file is never assembled in memory.
struct BinSource {
  // bytes: `data` written as it is. normals: `mesh`'s normals, unit length. quantized_positions,
  // quantized_normals: `mesh`'s, quantized (glb_document.hpp). short_indices: the uint32 indices
  // at `data` written as uint16.
  enum class Kind { bytes, normals, quantized_positions, quantized_normals, short_indices } kind;
  const void* data;
  const TriMesh* mesh;
  size_t offset, bytes;    // place in the binary chunk
};

// The one grid of a quantized file's positions: position = origin + step * q, q in [0, 65535].
struct QuantGrid {
  Vec3d origin;
  double step = 1;

  std::array<uint16_t, 3> quantize(const Vec3f& p) const {
    const auto q = [this](double v, double o) {
      return static_cast<uint16_t>(std::clamp(std::round((v - o) / step), 0.0, 65535.0));
    };
    return {q(p.x, origin.x), q(p.y, origin.y), q(p.z, origin.z)};
  }
  // The node matrix's factor that turns grid integers into millimetres (column-major).
  Transform dequantize() const {
    return {step, 0, 0, 0, 0, step, 0, 0, 0, 0, step, 0, origin.x, origin.y, origin.z, 1};
  }
};

// A unit normal as three normalised signed bytes (value / 127): of the 8 roundings around 127 n,
// the one closest in direction among those within 0.006 of unit length (the validator allows
// 0.00674), else the one closest to unit length.
std::array<int8_t, 3> quantize_normal(const Vec3f& n) {
  const double f[3] = {127.0 * n.x, 127.0 * n.y, 127.0 * n.z};
  std::array<int8_t, 3> best{0, 0, 127};
  double best_dot = -2, best_len_err = 2;
  bool best_ok = false;
  for (int corner = 0; corner < 8; ++corner) {
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(std::floor(f[k]) + ((corner >> k) & 1), -127.0, 127.0);
    const double len = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
    if (len == 0) continue;
    const double len_err = std::abs(len / 127.0 - 1.0);
    const double dot = (c[0] * n.x + c[1] * n.y + c[2] * n.z) / len;
    const bool ok = len_err <= 0.006;
    if ((ok && (!best_ok || dot > best_dot)) || (!ok && !best_ok && len_err < best_len_err)) {
      best = {int8_t(c[0]), int8_t(c[1]), int8_t(c[2])};
      best_dot = dot;
      best_len_err = len_err;
      best_ok = ok;
    }
  }
  return best;
}

// An accessor's min and max (POSITION's), as integers (quantized) or as doubles.
struct Bounds {
  std::array<double, 3> lo, hi;
  bool integers = false;
};

// The accessors and bufferViews as JSON text (the arrays' members, compact), and the binary
// sources they describe.
class GlbBuilder {
 public:
  GlbBuilder() {
    views_.begin_array();
    accessors_.begin_array();
  }
  // Reserves `bytes` as a new bufferView and an accessor over it; returns the accessor index.
  // `stride`, when not 0, is the view's byteStride (attributes padded to 4 bytes).
  size_t add_accessor(BinSource source, size_t count, int component_type, const char* type,
                      int target, bool normalized = false, size_t stride = 0,
                      const Bounds* bounds = nullptr) {
    size_ = (size_ + 3) / 4 * 4;
    source.offset = size_;
    size_ += source.bytes;
    views_.begin_object().member("buffer", 0).member("byteOffset", source.offset).member("byteLength", source.bytes);
    if (stride) views_.member("byteStride", stride);
    views_.member("target", target).end_object();
    sources_.push_back(source);
    accessors_.begin_object().member("bufferView", sources_.size() - 1).member("componentType", component_type);
    if (normalized) accessors_.member("normalized", true);
    accessors_.member("count", count).member("type", type);
    if (bounds) {
      for (const auto& [name, v] : {std::pair{"min", &bounds->lo}, std::pair{"max", &bounds->hi}}) {
        accessors_.key(name).begin_array();
        for (double x : *v) {
          if (bounds->integers) accessors_.value(int64_t(x));
          else accessors_.value(x);
        }
        accessors_.end_array();
      }
    }
    accessors_.end_object();
    return sources_.size() - 1;
  }
  size_t add_bytes(const void* data, size_t bytes, size_t count, int component_type,
                   const char* type, int target, bool normalized = false) {
    return add_accessor(BinSource{BinSource::Kind::bytes, data, nullptr, 0, bytes}, count,
                        component_type, type, target, normalized);
  }
  // The arrays' text, closed.
  std::string& views() { return views_.end_array().text(); }
  std::string& accessors() { return accessors_.end_array().text(); }
  const std::vector<BinSource>& sources() const { return sources_; }
  // The binary chunk's length, padded to 4 bytes.
  size_t bin_size() const { return (size_ + 3) / 4 * 4; }

 private:
  size_t size_ = 0;
  std::vector<BinSource> sources_;
  JsonText views_, accessors_;
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
      const Vec3f n = unit(v);
      std::memcpy(out + 12 * (v - begin), &n, 12);
    }
  }
  // Normals [begin, end) quantized (quantize_normal), 4 bytes each, the fourth 0.
  void fill_quantized(size_t begin, size_t end, char* out) {
    for (size_t v = begin; v < end; ++v) {
      const std::array<int8_t, 3> q = quantize_normal(unit(v));
      std::memcpy(out + 4 * (v - begin), q.data(), 3);
      out[4 * (v - begin) + 3] = 0;
    }
  }

 private:
  Vec3f unit(size_t v) {
    const Vec3d n = to_double(m_.normals[v]);
    const double len = norm(n);
    if (std::isfinite(len) && len > 1e-12) return to_float((1.0 / len) * n);
    const std::vector<Vec3d>& sum = sums();
    const double s = norm(sum[v]);
    return s > 0 && std::isfinite(s) ? to_float((1.0 / s) * sum[v]) : Vec3f{0, 0, 1};
  }

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

void write_matrix(JsonText& j, const Transform& t) {
  j.key("matrix").begin_array();
  for (double v : t) j.value(v);
  j.end_array();
}

void write_extras(JsonText& j, const GlbExtras& extras) {
  if (extras.empty()) return;
  j.key("extras").begin_object();
  for (const auto& [key, value] : extras) {
    j.key(key);
    std::visit([&j](const auto& v) { j.value(v); }, value);
  }
  j.end_object();
}

void write_material(JsonText& j, const GlbMaterial& m) {
  const Material& mat = m.material;
  const auto unit = [](float v) { return tidy(std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f)); };
  j.begin_object().member("name", m.name).key("pbrMetallicRoughness").begin_object();
  j.key("baseColorFactor").begin_array();
  j.value(unit(mat.base_color.r)).value(unit(mat.base_color.g)).value(unit(mat.base_color.b)).value(1.0);
  j.end_array();
  j.member("metallicFactor", unit(mat.metallic)).member("roughnessFactor", unit(mat.roughness));
  j.end_object().end_object();
}

// A mesh's vertex accessors; `none` where there is none.
struct Attributes {
  static constexpr size_t none = ~size_t{0};
  size_t position = none, normal = none, color = none;
};

void write_attributes(JsonText& j, const Attributes& a) {
  j.key("attributes").begin_object().member("POSITION", a.position);
  if (a.normal != Attributes::none) j.member("NORMAL", a.normal);
  if (a.color != Attributes::none) j.member("COLOR_0", a.color);
  j.end_object();
}

// The accessors of one mesh's vertices: POSITION with its bounds, NORMAL and COLOR_0 when asked;
// quantized on `grid` when there is one.
Attributes vertex_attributes(const GlbMesh& mesh, const std::optional<QuantGrid>& grid, GlbBuilder& b) {
  const TriMesh& m = *mesh.vertices;
  if (m.vertex_count() > std::numeric_limits<uint32_t>::max() - 1) {
    throw Error("glTF mesh '" + mesh.name + "' has too many vertices for uint32 indices");
  }
  Attributes attributes;
  if (grid) {
    std::array<uint16_t, 3> lo{65535, 65535, 65535}, hi{0, 0, 0};
    for (const Vec3f& p : m.positions) {
      const std::array<uint16_t, 3> q = grid->quantize(p);
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], q[k]), hi[k] = std::max(hi[k], q[k]);
    }
    const Bounds bounds{{double(lo[0]), double(lo[1]), double(lo[2])}, {double(hi[0]), double(hi[1]), double(hi[2])}, true};
    attributes.position = b.add_accessor(
        BinSource{BinSource::Kind::quantized_positions, nullptr, &m, 0, m.positions.size() * 8},
        m.positions.size(), kUnsignedShort, "VEC3", kArrayBuffer, false, 8, &bounds);
    if (mesh.normals) {
      attributes.normal = b.add_accessor(
          BinSource{BinSource::Kind::quantized_normals, nullptr, &m, 0, m.normals.size() * 4},
          m.normals.size(), kByte, "VEC3", kArrayBuffer, true, 4);
    }
  } else {
    Vec3f lo{std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
             std::numeric_limits<float>::max()};
    Vec3f hi{-lo.x, -lo.y, -lo.z};
    for (const Vec3f& p : m.positions) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
    static_assert(sizeof(Vec3f) == 12 && sizeof(Rgba8) == 4, "accessor data are written as they are");
    // float -> double is exact, so the validator's min/max comparison against the data holds.
    const Bounds bounds{{double(lo.x), double(lo.y), double(lo.z)}, {double(hi.x), double(hi.y), double(hi.z)}};
    attributes.position = b.add_accessor(
        BinSource{BinSource::Kind::bytes, m.positions.data(), nullptr, 0, m.positions.size() * 12},
        m.positions.size(), kFloat, "VEC3", kArrayBuffer, false, 0, &bounds);
    if (mesh.normals) {
      attributes.normal = b.add_accessor(
          BinSource{BinSource::Kind::normals, nullptr, &m, 0, m.normals.size() * 12},
          m.normals.size(), kFloat, "VEC3", kArrayBuffer);
    }
  }
  if (mesh.colors) {
    attributes.color = b.add_bytes(m.colors.data(), m.colors.size() * 4, m.colors.size(),
                                   kUnsignedByte, "VEC4", kArrayBuffer, true);
  }
  return attributes;
}

// The GLB container: header, JSON chunk and BIN chunk, the binary data streamed from its sources.
void write_container(std::string json, const GlbBuilder& b, const std::optional<QuantGrid>& grid,
                     std::ostream& out) {
  const size_t bin_size = b.bin_size();
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
    } else if (source.kind == BinSource::Kind::quantized_positions) {
      const TriMesh& m = *source.mesh;
      const QuantGrid g = *grid;
      pieces.records(m.positions.size(), 8, [&m, g](size_t v, char* p) {
        const std::array<uint16_t, 3> q = g.quantize(m.positions[v]);
        for (int k = 0; k < 3; ++k) put_le<uint16_t>(p + 2 * k, q[k]);
        put_le<uint16_t>(p + 6, 0);
        return p + 8;
      });
    } else if (source.kind == BinSource::Kind::short_indices) {
      const auto* indices = static_cast<const uint32_t*>(source.data);
      pieces.records(source.bytes / 2, 2, [indices](size_t i, char* p) {
        put_le<uint16_t>(p, static_cast<uint16_t>(indices[i]));
        return p + 2;
      });
    } else {
      // Normals, unit length, as floats (12 bytes) or quantized (4), filled piece by piece.
      const bool quantized = source.kind == BinSource::Kind::quantized_normals;
      const size_t size = quantized ? 4 : 12;
      UnitNormals& unit = *normals.emplace_back(std::make_unique<UnitNormals>(*source.mesh));
      pieces.items(source.mesh->normals.size(), kPieceBytes / size,
                   [&unit, quantized, size](size_t begin, size_t end, ChunkBuffer& buffer) {
                     char* p = buffer.room((end - begin) * size);
                     if (quantized) unit.fill_quantized(begin, end, p);
                     else unit.fill(begin, end, p);
                     buffer.commit(p + (end - begin) * size);
                     return buffer.view();
                   });
    }
    written = source.offset + source.bytes;
  }
  pad_to(bin_size);
  pieces.write(out);
}

// The grid over every position of the scene's meshes (glb_document.hpp).
QuantGrid scene_grid(const GlbScene& scene) {
  Vec3d lo{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
           std::numeric_limits<double>::max()};
  Vec3d hi{-lo.x, -lo.y, -lo.z};
  for (const GlbMesh& mesh : scene.meshes) {
    if (mesh.primitives.empty()) continue;
    for (const Vec3f& p : mesh.vertices->positions) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw Error("glTF mesh '" + mesh.name + "' has a position that is not finite; it cannot be quantized");
      }
      lo = {std::min(lo.x, double(p.x)), std::min(lo.y, double(p.y)), std::min(lo.z, double(p.z))};
      hi = {std::max(hi.x, double(p.x)), std::max(hi.y, double(p.y)), std::max(hi.z, double(p.z))};
    }
  }
  if (!(lo.x <= hi.x)) return QuantGrid{};  // no positions
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  return QuantGrid{lo, extent > 0 ? extent / 65535.0 : 1.0};
}

}  // namespace

void write_glb_scene(const GlbScene& scene, std::ostream& out) {
  GlbBuilder b;
  // The root is node 0 and the meshes' nodes follow it in order, so its children are 1..count.
  size_t count = 0;
  for (const GlbMesh& mesh : scene.meshes) count += mesh.primitives.empty() ? 0 : 1;
  JsonText nodes, meshes;
  nodes.begin_array().begin_object().member("name", kGltfRootName);
  write_matrix(nodes, kGltfRootMatrix);
  if (count > 0) {
    nodes.key("children").begin_array();
    for (size_t i = 1; i <= count; ++i) nodes.value(i);
    nodes.end_array();
  }
  nodes.end_object();
  meshes.begin_array();

  const std::optional<QuantGrid> grid = scene.quantize ? std::optional(scene_grid(scene)) : std::nullopt;
  size_t mesh_index = 0;
  for (const GlbMesh& mesh : scene.meshes) {
    if (mesh.primitives.empty()) continue;
    const Attributes attributes = vertex_attributes(mesh, grid, b);
    const bool short_indices = grid && mesh.vertices->positions.size() <= 65535;
    meshes.begin_object().member("name", mesh.name).key("primitives").begin_array();
    for (const GlbPrimitive& primitive : mesh.primitives) {
      static_assert(std::endian::native == std::endian::little, "GLB data are little-endian");
      const size_t n = primitive.indices.size();
      const size_t indices =
          short_indices
              ? b.add_accessor(BinSource{BinSource::Kind::short_indices, primitive.indices.data(),
                                         nullptr, 0, n * 2},
                               n, kUnsignedShort, "SCALAR", kElementArrayBuffer)
              : b.add_bytes(primitive.indices.data(), n * 4, n, kUnsignedInt, "SCALAR",
                            kElementArrayBuffer);
      meshes.begin_object();
      write_attributes(meshes, attributes);
      meshes.member("indices", indices).member("material", primitive.material).member("mode", 4);
      write_extras(meshes, primitive.extras);
      meshes.end_object();
    }
    meshes.end_array().end_object();
    nodes.begin_object().member("name", mesh.name).member("mesh", mesh_index++);
    if (grid) {
      write_matrix(nodes, multiply(mesh.matrix, grid->dequantize()));
    } else if (!is_identity(mesh.matrix)) {
      write_matrix(nodes, mesh.matrix);
    }
    write_extras(nodes, mesh.extras);
    nodes.end_object();
  }
  nodes.end_array();
  meshes.end_array();

  JsonText gltf;
  gltf.begin_object().key("asset").begin_object().member("version", "2.0").member("generator", "segmesh");
  gltf.key("extras").begin_object().member("units", "mm").member("space", "LPS");
  gltf.member("root_transform",
              "node segmesh_scene maps LPS millimetres to glTF metres: gltf = 0.001 * (x, z, -y) "
              "(x Left, +Y Superior, +Z Anterior)");
  gltf.end_object().end_object();
  if (grid && count > 0) {
    for (const char* key : {"extensionsUsed", "extensionsRequired"}) {
      gltf.key(key).begin_array().value("KHR_mesh_quantization").end_array();
    }
  }
  gltf.member("scene", 0);
  gltf.key("scenes").begin_array().begin_object().member("name", "segmesh");
  gltf.key("nodes").begin_array().value(0).end_array().end_object().end_array();
  gltf.key("nodes").raw(nodes.text());
  if (count > 0) {
    gltf.key("meshes").raw(meshes.text());
    gltf.key("materials").begin_array();
    for (const GlbMaterial& m : scene.materials) write_material(gltf, m);
    gltf.end_array();
    gltf.key("accessors").raw(b.accessors());
    gltf.key("bufferViews").raw(b.views());
  }
  if (b.bin_size() > 0) {
    gltf.key("buffers").begin_array().begin_object().member("byteLength", b.bin_size()).end_object().end_array();
  }
  gltf.end_object();
  write_container(std::move(gltf.text()), b, grid, out);
}

}  // namespace segmesh::mesh_io
