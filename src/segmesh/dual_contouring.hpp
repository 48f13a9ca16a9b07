// Dual Contouring (Ju, Losasso, Schaefer and Warren 2002) with one vertex per sheet, so every part
// stays closed and manifold.
//
// Hermite data: every sign-changing edge gets its crossing and the field gradient there, divided
// by the spacing: on a grey-value field from a Catmull-Rom cubic along the edge and ENO
// differences (edge_intersection.hpp's cubic_edge_crossing), on a 0/1 field the edge's midpoint
// and the corners' central differences or Sobel gradients interpolated. Vertices: every sheet of the surface inside a cell (dual_contouring_table.hpp: the
// pieces of the cell's Marching Cubes surface) gets the minimiser of the QEF of its crossings
// (qef.hpp), solved about the mass point with singular values below svd_eps * the largest dropped,
// and kept inside its cell (on a grey-value field, the cell grown by cell_reach; for a cell with
// several sheets, inside the bounding box of the sheet's crossings) by moving it back towards the
// mass point. Polygons: every sign-changing edge
// gets the polygon of the sheets around it — a quad, or a pentagon/hexagon where a cell holds two
// sheets at that edge — split into triangles along the diagonals that give the best radii ratios,
// wound counter-clockwise seen from outside.
//
// This is the polygon set the octree recursion (cellProc / faceProc / edgeProc) yields over an
// unsimplified octree — one polygon per minimal sign-changing edge — computed directly on the grid
// in the manner of marching_cubes.hpp, on the field's inside bits (inside_bits.hpp: 64 grid points
// to a word): passes over rows of cells in parallel (per word of 64 cells the non-trivial and the
// rare ones, count the polygons, solve the sheets, emit the polygons), prefix sums between them,
// disjoint output ranges, identical for any thread count. A cell's vertex id is a popcount in its
// row, so no list of cells is stored. On a 0/1 field each distinct 4 x 4 x 4 neighbourhood's QEF
// is solved once per thread (for a single sheet, once per mirror class; DcNeighbourhoods below
// shares them between the parts of a scene). Adaptive simplification
// (`tolerance_mm` > 0) clusters the cells of an octree built over the grid bottom-up: a node's
// children collapse into one vertex where the merged QEF error stays within the tolerance and Ju
// et al.'s topology tests hold (one sheet, no sign change hidden at edge, face or cell midpoints),
// so flat regions get fewer, larger triangles without changing the surface's topology.
//
// Guarantees: on a padded field (background on the outer layer) the mesh is closed, edge-manifold
// and consistently wound, with the connectivity of marching_cubes.hpp.
// Cost: one pass over the field to pack its bits (for a label part, its runs set them: no mask),
// then a few word operations per 64 cells per pass plus O(non-trivial cells), and one QEF solve per
// sheet (on a 0/1 field, per distinct neighbourhood, or per mirror class of the points a single
// sheet depends on); memory one bit per grid point, 20 bytes per word of cells (its cells, rare
// cells and first vertex), 14 per row of cells, the solved neighbourhoods, and the output.
#pragma once

#include <cstdint>
#include <memory>

#include "segmesh/components.hpp"
#include "segmesh/connectivity.hpp"
#include "segmesh/gradient.hpp"
#include "segmesh/progress.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

// QEF vertices stay this fraction of their cell away from the cell's faces, so vertices of
// neighbouring cells never coincide (zero-area triangles).
inline constexpr double kDcCellMargin = 0.05;

// On a grey-value field a single sheet's QEF vertex may leave its cell by up to this fraction of
// the cell on each side: where a sharp edge passes near a cell without crossing it, the cell's
// tangent planes still meet on the edge, and clamping the vertex to its own cell would chamfer it.
// A 0/1 field's vertices stay kDcCellMargin inside their cells (its tangent planes describe voxel
// stairs, not features).
inline constexpr double kDefaultDcCellReach = 0.25;

// The relative singular value cut-off of the QEF solve (qef.hpp), `--dc-svd-eps`.
inline constexpr double kDefaultDcSvdEps = 0.5;

// The Hermite data of a grey-value field: linear interpolation of the crossing and of the corners'
// gradients, or the higher-order interpolation of edge_intersection.hpp (cubic_edge_crossing: a
// Catmull-Rom crossing, ENO gradients), which keeps sharp edges closer to where they are. 0/1
// fields (label parts) always take the linear data: their crossings are edge midpoints.
enum class DcHermite { linear, cubic };

struct DcOptions {
  double iso = 0.5;
  int connectivity = kDefaultConnectivity;       // 6, 18 or 26: which sheets exist (see above)
  NormalMethod normals = NormalMethod::central;  // the Hermite normals
  double svd_eps = kDefaultDcSvdEps;  // singular values below svd_eps * the largest are dropped
  DcHermite hermite = DcHermite::cubic;  // grey-value fields' Hermite data (above)
  double cell_reach = kDefaultDcCellReach;  // grey-value fields: how far a vertex may leave its cell
  double tolerance_mm = 0;   // > 0: adaptive simplification with this QEF error (RMS distance, mm)
  bool vertex_normals = true;  // false: no normals (smoothing recomputes them); kept when simplifying
};

template <class T>
TriMesh dual_contouring(const Volume<T>& field, const DcOptions& options,
                        Progress& progress = null_progress());

// The QEF vertices of binary cells already solved, by neighbourhood, for the parts of one label
// map to share: extract_parts (pipeline.hpp) passes one to every part, so a neighbourhood that
// recurs in several parts (identical screws, bones of one scan) is solved once per thread for the
// whole scene. Made for one grid spacing and direction and one connectivity, normal operator,
// svd_eps and choice of vertex normals; dual_contouring throws std::logic_error when given it with
// others. Thread-safe.
class DcNeighbourhoods {
 public:
  DcNeighbourhoods(const Grid& grid, const DcOptions& options);
  ~DcNeighbourhoods();
  struct Tables;  // one table per thread (detail/dc_neighbourhood_cache.hpp)
  const std::unique_ptr<Tables> tables;
};

// Dual Contouring of one connected component of a label map (its 0/1 mask, options.iso
// ignored): the inside bits come straight from the component's runs and the Hermite data from the
// bits around each cell, so no mask is built; the mesh is the one
// dual_contouring(component_mask(...)) gives. `solved`: the scene's solved neighbourhoods (above),
// or nullptr for the part's own.
TriMesh dual_contouring(const Grid& grid, const Components& components, const Component& component,
                        const DcOptions& options, Progress& progress = null_progress(),
                        DcNeighbourhoods* solved = nullptr);

extern template TriMesh dual_contouring(const Volume<uint8_t>&, const DcOptions&, Progress&);
extern template TriMesh dual_contouring(const Volume<int32_t>&, const DcOptions&, Progress&);
extern template TriMesh dual_contouring(const Volume<float>&, const DcOptions&, Progress&);

}  // namespace segmesh
