#include "segmesh_render/detail/gpu_mesh.hpp"

#include "segmesh/quality.hpp"
#include "segmesh/vec3.hpp"
#include "segmesh_render/mat4.hpp"

namespace segmesh::render {
namespace {

uint64_t fnv(uint64_t h, const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 0x100000001B3ull;
  return h;
}

// The count of `v` and `samples` entries spread evenly over it, hashed into `h`.
template <class T>
uint64_t sample_hash(uint64_t h, const std::vector<T>& v, size_t samples) {
  const size_t n = v.size();
  h = fnv(h, &n, sizeof n);
  if (n == 0) return h;
  for (size_t k = 0; k < samples; ++k) {
    const size_t i = samples == 1 ? 0 : k * (n - 1) / (samples - 1);
    h = fnv(h, &v[i], sizeof(T));
  }
  return h;
}

std::vector<Vec3f> vertex_normals(const TriMesh& m) {
  std::vector<Vec3d> sum(m.positions.size());
  for (size_t t = 0; t + 2 < m.indices.size(); t += 3) {
    const uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
    const Vec3d pa = to_double(m.positions[a]), pb = to_double(m.positions[b]),
                pc = to_double(m.positions[c]);
    const Vec3d n = cross(pb - pa, pc - pa);  // area-weighted
    sum[a] = sum[a] + n;
    sum[b] = sum[b] + n;
    sum[c] = sum[c] + n;
  }
  std::vector<Vec3f> out(sum.size());
  for (size_t i = 0; i < sum.size(); ++i) out[i] = to_float(normalized(sum[i]));
  return out;
}

// Fills `buffer` (made when 0) with `values` and feeds it to attribute `location` of the bound
// vertex array: `components` of `type` per vertex, tightly packed; `normalized` maps integers
// to [0, 1].
template <class T>
void upload_attribute(GLuint& buffer, GLuint location, const std::vector<T>& values,
                      GLint components, GLenum type, GLboolean normalized) {
  if (!buffer) glGenBuffers(1, &buffer);
  glBindBuffer(GL_ARRAY_BUFFER, buffer);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(values.size() * sizeof(T)), values.data(),
               GL_STATIC_DRAW);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, components, type, normalized, sizeof(T), nullptr);
}

void upload_colors(GpuMesh& g, const std::vector<Rgba8>& colors) {
  glBindVertexArray(g.vao);
  upload_attribute(g.colors, 2, colors, 4, GL_UNSIGNED_BYTE, GL_TRUE);
  glBindVertexArray(0);
}

void upload(GpuMesh& g, const TriMesh& mesh) {
  g.release();
  g.fingerprint = mesh_fingerprint(mesh);
  g.bounds = mesh_bounds(mesh);
  if (mesh.empty() || mesh.positions.empty()) return;
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  upload_attribute(g.positions, 0, mesh.positions, 3, GL_FLOAT, GL_FALSE);
  const std::vector<Vec3f> computed =
      mesh.normals.size() == mesh.positions.size() ? std::vector<Vec3f>{} : vertex_normals(mesh);
  upload_attribute(g.normals, 1, computed.empty() ? mesh.normals : computed, 3, GL_FLOAT, GL_FALSE);
  glGenBuffers(1, &g.indices);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.indices);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(uint32_t)),
               mesh.indices.data(), GL_STATIC_DRAW);
  g.index_count = GLsizei(mesh.indices.size());
  glBindVertexArray(0);
  if (mesh.colors.size() == mesh.positions.size()) {
    upload_colors(g, mesh.colors);
    g.has_colors = true;
  }
}

}  // namespace

void GpuMesh::release() {
  if (vao) glDeleteVertexArrays(1, &vao);
  GLuint buffers[] = {positions, normals, colors, indices};
  for (GLuint b : buffers)
    if (b) glDeleteBuffers(1, &b);
  *this = GpuMesh{};
}

uint64_t mesh_fingerprint(const TriMesh& m) {
  uint64_t h = 0xCBF29CE484222325ull;
  h = sample_hash(h, m.positions, 97);
  h = sample_hash(h, m.indices, 97);
  h = sample_hash(h, m.normals, 31);
  h = sample_hash(h, m.colors, 31);
  return h;
}

GpuMeshCache::~GpuMeshCache() {
  for (GpuMesh& m : meshes_) m.release();
}

int64_t GpuMeshCache::sync(const Scene& scene) {
  int64_t uploaded = 0;
  for (size_t i = scene.parts.size(); i < meshes_.size(); ++i) meshes_[i].release();
  meshes_.resize(scene.parts.size());
  for (size_t i = 0; i < scene.parts.size(); ++i) {
    GpuMesh& g = meshes_[i];
    const TriMesh& m = scene.parts[i].mesh;
    if (!g.stale && g.fingerprint == mesh_fingerprint(m) && (g.vao || m.empty())) continue;
    upload(g, m);
    ++uploaded;
  }
  return uploaded;
}

void GpuMeshCache::invalidate(size_t index) {
  if (index < meshes_.size()) meshes_[index].stale = true;
}

void GpuMeshCache::ensure_quality_colors(size_t index, const TriMesh& mesh) {
  GpuMesh& g = meshes_[index];
  if (g.has_colors || g.quality_colors) return;
  upload_colors(g, quality_colors(vertex_quality(mesh)));
  g.quality_colors = true;
}

}  // namespace segmesh::render
