// Measures of a triangle mesh that say whether it can be trusted: area, enclosed volume, and the
// topology checks (boundary and non-manifold edges, winding errors, shells, Euler characteristic).
//
// Edges are found through a compressed per-vertex list of outgoing half-edges, O(triangles) time
// and memory, no hashing. The enclosed volume uses the divergence theorem (sum of signed
// tetrahedra against the mesh's centroid, in double), positive for a closed mesh wound
// counter-clockwise seen from outside.
#pragma once

#include <cstdint>

#include "segmesh/tri_mesh.hpp"

namespace segmesh {

struct MeshMeasures {
  int64_t vertices = 0;           // vertices used by at least one triangle
  int64_t triangles = 0;
  int64_t edges = 0;              // undirected
  double area_mm2 = 0;
  double volume_mm3 = 0;          // signed enclosed volume
  int64_t boundary_edges = 0;     // used by one triangle
  int64_t nonmanifold_edges = 0;  // used by more than two triangles
  int64_t winding_errors = 0;     // used twice, both times in the same direction
  int64_t degenerate_triangles = 0;  // zero area (repeated or collinear vertices)
  int64_t shells = 0;             // connected components of triangles
  int64_t euler = 0;              // vertices - edges + triangles

  // Closed and edge-manifold: every edge in exactly two triangles, in opposite directions.
  bool closed() const {
    return triangles > 0 && boundary_edges == 0 && nonmanifold_edges == 0 && winding_errors == 0;
  }
};

MeshMeasures measure_mesh(const TriMesh& mesh);

}  // namespace segmesh
