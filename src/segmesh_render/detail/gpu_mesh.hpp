// GPU copies of the scene's meshes: one vertex array per part (positions, normals, colours,
// triangle indices) and the cache that keeps them in step with a Scene.
//
// Why: uploading a mesh of a million triangles takes far longer than drawing it, so the renderer
// uploads a part only when it is new or its mesh changed, and the frame reuses the rest.
// Guarantees: a part's mesh counts as changed when its counts or a fingerprint of sampled
// vertices, indices, normals and colours differ (any replaced or smoothed mesh), or when it was
// invalidated; normals missing from the mesh are computed (area-weighted vertex normals); a
// mesh's own colours are uploaded with it, quality colours only when a frame asks for them.
// Needs a current OpenGL 3.3 core context for every call but fingerprinting. Cost: sync hashes
// about 250 entries per part and uploads only what changed.
#pragma once

#include <epoxy/gl.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/scene.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh_render/camera.hpp"

namespace segmesh::render {

struct GpuMesh {
  GLuint vao = 0, positions = 0, normals = 0, colors = 0, indices = 0;
  GLsizei index_count = 0;
  uint64_t fingerprint = 0;
  bool stale = false;
  bool has_colors = false;      // the colour buffer holds the mesh's own colours
  bool quality_colors = false;  // the colour buffer holds colours computed from the radii ratio
  Bounds bounds;                // local (before the part's transform)

  void release();  // frees the buffers; back to an empty GpuMesh
};

// Counts and a hash of sampled entries: cheap, and changes whenever the pipeline replaces or
// smooths a mesh (every vertex moves).
uint64_t mesh_fingerprint(const TriMesh& mesh);

// One GpuMesh per part of the last synced scene, by index in Scene::parts.
class GpuMeshCache {
 public:
  GpuMeshCache() = default;
  ~GpuMeshCache();
  GpuMeshCache(const GpuMeshCache&) = delete;
  GpuMeshCache& operator=(const GpuMeshCache&) = delete;

  // Uploads the parts that are new, changed or invalidated and frees those past the scene's
  // parts; returns how many parts it uploaded.
  int64_t sync(const Scene& scene);
  // Part `index` is uploaded again by the next sync; an index past the cache is ignored.
  void invalidate(size_t index);
  // Gives part `index` colours from its radii ratio (quality.hpp) unless its mesh has colours of
  // its own or they were computed before.
  void ensure_quality_colors(size_t index, const TriMesh& mesh);

  size_t size() const { return meshes_.size(); }
  const GpuMesh& operator[](size_t index) const { return meshes_[index]; }

 private:
  std::vector<GpuMesh> meshes_;
};

}  // namespace segmesh::render
