// Marching Cubes (Lorensen and Cline 1987) with a complete, topologically consistent case table
// (marching_cubes_table.hpp) and extraction in the manner of VTK's flying edges: a counting pass
// over z-planes in parallel, prefix sums, then a pass that fills disjoint output ranges. No locks,
// no hash maps, and the output is identical for any number of threads.
//
// [in]  field    values at grid points, with the field's Grid placing them in the world. A grid
//                point is inside when its value >= iso (NaN is outside). Only cells between grid
//                points are visited: pad the field with background to close surfaces at its border.
// [in]  options  iso value, the connectivity the ambiguous faces follow (6, 18, 26), the
//                gradient operator for normals.
// [out] a TriMesh in world millimetres: one shared vertex per cut edge, linearly interpolated
//       (kept at least kMinEdgeFraction away from the edge's ends, so a corner value equal to iso
//       never collapses vertices into zero-area triangles), unit normals from the field gradient
//       pointing outwards (towards lower values) unless options.vertex_normals is false, triangles counter-clockwise seen from outside —
//       also for mirrored grids (negative direction determinant), whose winding is flipped.
// Guarantees: for a padded field the mesh is closed, edge-manifold and consistently wound.
// Cost: O(cells) time in two passes over the field, O(vertices + triangles) memory plus two
// planes of edge ids per worker.
#pragma once

#include <cstdint>

#include "segmesh/gradient.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

struct McOptions {
  double iso = 0.5;                              // a label indicator (0/1) is contoured at 0.5
  int connectivity = 26;                         // 6, 18 or 26: see marching_cubes_table.hpp
  NormalMethod normals = NormalMethod::central;  // central differences or Sobel
  // False: no normals (TriMesh::normals left empty), for meshes whose normals are recomputed from
  // the triangles anyway (smoothing does); saves the gradient at both ends of every cut edge.
  bool vertex_normals = true;
};

template <class T>
TriMesh marching_cubes(const Volume<T>& field, const McOptions& options,
                       Progress& progress = null_progress());

extern template TriMesh marching_cubes(const Volume<uint8_t>&, const McOptions&, Progress&);
extern template TriMesh marching_cubes(const Volume<int32_t>&, const McOptions&, Progress&);
extern template TriMesh marching_cubes(const Volume<float>&, const McOptions&, Progress&);

}  // namespace segmesh
