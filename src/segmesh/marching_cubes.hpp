// Marching Cubes (Lorensen and Cline 1987) with a complete, topologically consistent case table
// (marching_cubes_table.hpp) and extraction in the manner of VTK's flying edges: a counting pass
// over rows in parallel, prefix sums, then a pass that fills disjoint output ranges. No locks, no
// hash maps, no plane of edge ids, and the output is identical for any number of threads.
//
// [in]  field    values at grid points, with the field's Grid placing them in the world. A grid
//                point is inside when its value >= iso (NaN is outside). Only cells between grid
//                points are visited: pad the field with background to close surfaces at its border.
// [in]  options  iso value, the connectivity the ambiguous faces follow (6, 18, 26), the
//                gradient operator for normals.
// [out] a TriMesh in world millimetres: one shared vertex per cut edge, linearly interpolated
//       (kept at least kMinEdgeFraction away from the edge's ends, so a corner value equal to iso
//       never collapses vertices into zero-area triangles), unit normals from the field gradient
//       pointing outwards (towards lower values) unless options.vertex_normals is false,
//       triangles counter-clockwise seen from outside — also for mirrored grids (negative
//       direction determinant), whose winding is flipped.
// Guarantees: for a padded field the mesh is closed, edge-manifold and consistently wound.
// Cost: one pass over the field to trim its rows (row_trim.hpp), then O(grid points in the
// trimmed rows) per pass; O(vertices + triangles) memory plus a few counters per row.
#pragma once

#include <cstdint>

#include "segmesh/components.hpp"
#include "segmesh/connectivity.hpp"
#include "segmesh/gradient.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh/volume.hpp"
namespace segmesh {

struct McOptions {
  double iso = 0.5;                              // a label indicator (0/1) is contoured at 0.5
  int connectivity = kDefaultConnectivity;  // 6, 18 or 26: see marching_cubes_table.hpp
  NormalMethod normals = NormalMethod::central;  // central differences or Sobel
  // False: no normals (TriMesh::normals left empty), for meshes whose normals are recomputed from
  // the triangles anyway (smoothing does); saves the gradient at both ends of every cut edge.
  bool vertex_normals = true;
};

template <class T>
TriMesh marching_cubes(const Volume<T>& field, const McOptions& options,
                       Progress& progress = null_progress());

// The surface of one connected component of a label map (its voxels contoured as a 0/1 indicator at
// 0.5, options.iso ignored), straight from the component's runs (run_scan.hpp): no mask is built
// and no voxel is looked at, so the cost is the component's run ends plus the output, whatever its
// bounding box. The mesh is the one marching_cubes(component_mask(...)) gives (the same triangles
// on the same vertices; positions agree to float rounding). With options.vertex_normals the
// normals need the field's gradient, and the mask is built and meshed instead.
TriMesh marching_cubes(const Grid& grid, const Components& components, const Component& component,
                       const McOptions& options, Progress& progress = null_progress());

extern template TriMesh marching_cubes(const Volume<uint8_t>&, const McOptions&, Progress&);
extern template TriMesh marching_cubes(const Volume<int32_t>&, const McOptions&, Progress&);
extern template TriMesh marching_cubes(const Volume<float>&, const McOptions&, Progress&);

}  // namespace segmesh
