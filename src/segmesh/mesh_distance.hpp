// Distances between points and triangle meshes, and between two meshes.
//
// Point to triangle: the Voronoi-region method of Ericson ("Real-Time Collision Detection", 2005,
// section 5.1.5, ClosestPtPointTriangle): the point is classified against the vertex, edge and face
// regions of the triangle by dot products and the closest point of that feature is returned. Two
// changes make it total and better conditioned: the face-region point is the orthogonal projection
// onto the plane (instead of a barycentric combination, whose rounding grows as the triangle gets
// thin), and a triangle whose corners are collinear to working precision (sin of the angle at its
// first corner <= 1e-8, which includes zero-length edges and repeated points) is treated as its
// three edges, i.e. as segments or a point. Either way the result is within about 1e-8 of the
// triangle's size of the exact answer.
//
// Point to mesh: a bounding volume hierarchy over the triangles, searched node by node nearest box
// first; a node whose box is not closer than the best triangle found so far is skipped, so the
// search stops once no closer triangle can exist and returns the exact minimum over all triangles.
//
// Why a BVH and not a uniform grid: the queries of mesh_deviation and of planning tools are often
// far from the surface (a misregistered implant, a point outside the scene's box) and a scene's
// parts are far apart with little in between (bone and screws); a grid must walk rings of empty
// cells in both cases and needs a cell size that suits every triangle size at once (decimated
// meshes mix very different sizes). A BVH's box lower bounds handle both, its depth is logarithmic
// whatever the geometry, and it needs no tuning.
//
// The tree is complete and balanced: the triangles are split at the median centroid along the
// longest axis of their centroid box, level by level, into 2^k leaves of 4 to 8 triangles. Its
// shape therefore depends only on the triangle count, nodes sit at implicit heap positions
// (children of i at 2i+1, 2i+2, no pointers), and the build is parallel (oneTBB) yet identical for
// any thread count. Each node's box is oriented along the node's mean normal (the OBB of
// Gottschalk, Lin and Manocha, "OBBTree", SIGGRAPH 1996, with the normal instead of principal axes)
// or axis-aligned, whichever has the smaller volume. On a smooth surface an oriented box is as thin
// as the surface bends over the node, where an axis-aligned box is about as thick as the node is
// wide; that slack decides how many nearly equidistant triangles a query must look at: with
// axis-aligned boxes, queries from points far outside or deep inside a 1.5 M triangle sphere tested
// thousands of triangles, with oriented boxes about a hundred. Each leaf's
// triangles are stored by value in leaf order, so a leaf is one contiguous read and MeshDistance
// keeps no reference to the mesh.
//
// Guarantees: distance() is the minimum over all triangles of the point-triangle distance above (it
// can differ from a brute-force loop only by rounding, when two triangles are equally close to the
// last bit); distance to an empty mesh is +infinity. mesh_deviation is parallel and gives identical
// results for any thread count.
//
// Cost: construction O(n log n) time (a linear selection and a projection of the node's corners per
// level), 50 to 70 bytes per triangle. A query visits O(log n) nodes on smooth surfaces, more where
// many triangles are equidistant from it (near the centre of a sphere); far from the surface a
// query's time is mostly cache misses.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "segmesh/tri_mesh.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

// The point of the triangle (a, b, c) closest to p, as described above; degenerate triangles
// (collinear corners, repeated corners) are handled as segments or a point.
Vec3d closest_point_on_triangle(Vec3d p, Vec3d a, Vec3d b, Vec3d c);

// The squared distance from p to that closest point: the exact test of the searches.
inline double point_triangle_distance2(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d d = p - closest_point_on_triangle(p, a, b, c);
  return dot(d, d);
}

// The squared distance from p to the nearest corner of (a, b, c): an upper bound of the one
// above, which settles "within a limit" questions without the exact test when it is small enough.
inline double nearest_corner_distance2(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  return std::min({dot(p - a, p - a), dot(p - b, p - b), dot(p - c, p - c)});
}

// The point of the segment [a, b] closest to p; a when a == b.
Vec3d closest_point_on_segment(Vec3d p, Vec3d a, Vec3d b);

class MeshDistance {
 public:
  // Indexes the triangles of `mesh` (its positions and indices); the mesh may be destroyed
  // afterwards. Preconditions: every index is in range and the positions are finite.
  explicit MeshDistance(const TriMesh& mesh);

  // Unsigned distance from p to the closest point on any triangle; +infinity for an empty mesh.
  double distance(Vec3d p) const;
  // The same when the mesh has a point at distance `upper_bound` from p (a known point on it):
  // the search skips everything farther, which makes it several times faster when the bound is
  // tight. The result equals distance(p) up to rounding (when the known point is the closest).
  double distance(Vec3d p, double upper_bound) const;
  // That closest point; +infinity in every coordinate for an empty mesh. When several triangles
  // are equally close, the one met first in the tree's fixed order wins.
  Vec3d closest_point(Vec3d p) const;

  size_t triangle_count() const { return triangles_.size(); }

 private:
  // The points x with lo[k] <= axis[k] . x <= hi[k]: an oriented box (rows of axis nearly
  // orthonormal), or an axis-aligned one (axis the identity).
  struct Box {
    float axis[3][3];
    float lo[3], hi[3];
  };
  struct Triangle {
    Vec3f a, b, c;
  };
  struct Hit {
    Vec3d point;
    double distance2;
  };

  void build_boxes();
  Hit nearest(Vec3d p, double bound2 = std::numeric_limits<double>::infinity()) const;
  // Triangles [begin, end) of leaf `leaf` (0 .. 2^levels_ - 1).
  size_t leaf_begin(uint64_t leaf) const { return (leaf * triangles_.size()) >> levels_; }

  int levels_ = 0;                   // the leaves are the nodes of depth levels_
  std::vector<Box> boxes_;           // complete binary tree in heap order, 2^(levels_+1) - 1 nodes
  std::vector<Triangle> triangles_;  // in leaf order
};

// Symmetric surface deviation between two meshes, in the meshes' units (mm).
struct Deviation {
  double hausdorff = 0;  // largest sample distance of either direction
  double mean = 0;       // mean over the samples of both directions
  double p95 = 0;        // 95th percentile over the samples of both directions (numpy's linear)
};

// Samples each mesh at its vertices used by a triangle plus the centroid of every triangle, and
// measures them against the other mesh. When both meshes share their triangles (same vertex count
// and indices: a mesh and its smoothed copy) it is moved_mesh_deviation (moved_mesh_deviation.hpp)
// with every sample measured: the same numbers from a tree on the triangles' own order, each
// search bounded by the sample's counterpart. Otherwise (a mesh and its decimated copy, two
// extractions):
// - Each mesh gets an OrderedTriangleTree (detail/ordered_triangle_tree.hpp), on its triangles
//   in Morton order when it has no more triangles than the other mesh, else on its own order
//   (sorting a mesh much larger than the samples its tree serves costs more than their searches).
// - Every search is bounded and started by the nearest triangles of the block's last searches.
// - Above 2 x kDeviationStatisticSamples samples in both directions together, the mean and the
//   95th percentile are taken over a stratified subset (detail/deviation_strata.hpp), one stride
//   for both directions so that the subset keeps their proportions: within 0.3 % of the full
//   numbers on the phantom's decimated parts and make_big.py's bone (docs/PERFORMANCE.md); the
//   Hausdorff distance stays the exact largest over every sample: a sample left out is searched
//   only when its distance to one of the recent nearest triangles exceeds the largest so far,
//   and that search stops at the first triangle within it.
// Below the limit every sample is measured and the numbers are the brute-force ones (up to the
// rounding of the sum). deviation(a, b) == deviation(b, a) exactly, for any number of threads.
// Two meshes without triangles deviate by 0; when only one is empty, every number is +infinity.
Deviation mesh_deviation(const TriMesh& a, const TriMesh& b);

}  // namespace segmesh
