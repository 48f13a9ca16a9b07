// Measures of a triangle mesh that say whether it can be trusted: area, enclosed volume, and the
// topology checks (boundary and non-manifold edges, non-manifold vertices, winding errors, shells,
// Euler characteristic). The definitions are those of ../shared/tools/mesh_metrics.py, the script
// that scores every program's meshes for the comparison tables, so the numbers mean the same thing.
//
// Edges are found through a compressed per-vertex list of outgoing half-edges, O(triangles) time
// and memory, no hashing. Each half-edge a -> b also records the third corner of its triangle,
// which is what the fans around a vertex are made of: the triangles at a vertex v, linked where
// two of them share an edge at v, fall into one or more fans; a pinch point (two cones touching
// at their tips) has two. Counting the fans costs O(k log k) for a vertex of k triangles.
//
// The enclosed volume is the divergence theorem's sum of signed tetrahedra against the origin,
// (1/6) sum a . (b x c), positive for a closed mesh wound counter-clockwise seen from outside. It
// is evaluated against the centroid of the vertices, in double, plus the exact correction
// (1/3) centroid . (sum of the triangles' area vectors); the correction vanishes for a closed
// mesh, and keeps an open mesh's value equal to the usual origin-based one (mesh_metrics.py, VTK).
//
// Degenerate input is measured, not rejected: a triangle that repeats a vertex index gives an edge
// from that vertex to itself (counted once per use, length 0), and the repeated vertex counts as
// non-manifold, as in mesh_metrics.py.
#pragma once

#include <cstdint>
#include <vector>

#include "segmesh/tri_mesh.hpp"

namespace segmesh {

struct MeshMeasures {
  int64_t vertices = 0;               // vertices used by at least one triangle
  int64_t triangles = 0;
  int64_t edges = 0;                  // undirected
  double area_mm2 = 0;
  double volume_mm3 = 0;              // signed enclosed volume
  double mean_edge_length_mm = 0;     // over the undirected edges
  int64_t boundary_edges = 0;         // used by one triangle
  int64_t nonmanifold_edges = 0;      // used by more than two triangles
  // Vertices whose triangles form more than one fan (edge-connected group around the vertex):
  // pinch points, where closed surfaces or sheets touch at a single vertex.
  int64_t nonmanifold_vertices = 0;
  int64_t winding_errors = 0;         // used twice, both times in the same direction
  int64_t degenerate_triangles = 0;   // zero area (repeated or collinear vertices)
  int64_t shells = 0;                 // connected components of triangles (via shared vertices)
  int64_t euler = 0;                  // vertices - edges + triangles

  // Closed and edge-manifold: every edge in exactly two triangles, in opposite directions.
  bool closed() const {
    return triangles > 0 && boundary_edges == 0 && nonmanifold_edges == 0 && winding_errors == 0;
  }
};

// Precondition: every index is below mesh.positions.size().
MeshMeasures measure_mesh(const TriMesh& mesh);

// Only the signed enclosed volume (as measure_mesh computes it), without the topology checks.
double enclosed_volume(const TriMesh& mesh);
// The same of the surface with these positions and triangles (a mesh's triangles with the
// positions it had before smoothing, say).
double enclosed_volume(const std::vector<Vec3f>& positions, const std::vector<uint32_t>& indices);

// Only the area of the mesh's triangles (mm², as measure_mesh sums it).
double surface_area(const TriMesh& mesh);

}  // namespace segmesh
