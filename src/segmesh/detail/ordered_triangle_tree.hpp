// The closest triangles of a mesh in a tree built on the triangles' own order, for exact point to
// mesh distances that cost one pass to set up (moved_mesh_deviation.cpp, the report's contacts in
// scene_measures.cpp).
//
// Extraction emits triangles row by row, plane by plane, so runs of consecutive triangles are
// already compact in space: the leaves are runs of kOrderedLeaf consecutive triangles, their
// axis-aligned boxes merged bottom-up into a complete binary tree in heap order (children of i
// at 2i+1 and 2i+2). No sort, no copy of the triangles: the tree reads the mesh's own arrays,
// which must outlive it. Memory: 48 bytes per leaf pair, about 3 bytes per triangle. Searches are
// exact whatever the order; a scattered order only makes them slower (docs/PERFORMANCE.md: a
// Morton order was tried and was slower than the extraction's own).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "segmesh/vec3.hpp"

namespace segmesh {

// Points one nearest2_group call searches at most.
inline constexpr size_t kTreeGroup = 16;

class OrderedTriangleTree {
 public:
  static constexpr size_t kNoStart = std::numeric_limits<size_t>::max();

  // The n triangles idx[3t..3t+2] over the positions pos. Precondition: n > 0, indices in range.
  OrderedTriangleTree(const Vec3f* pos, const uint32_t* idx, size_t n);

  // The squared distance from p to the closest triangle when it is below bound2, else bound2.
  // With `start`, the search begins with the leaf of that triangle (where a caller expects the
  // closest one). As soon as a corner or a triangle at `enough2` or below is found, in the start
  // leaf or anywhere later, that value is returned: a caller that only needs to know whether the
  // distance exceeds a value skips the rest of the search. With `nearest`, the triangle of the
  // value returned is written there when one below bound2 was found (else it is left as it is).
  double nearest2(Vec3d p, double bound2 = std::numeric_limits<double>::infinity(),
                  size_t start = kNoStart, double enough2 = -1, size_t* nearest = nullptr) const;

  // The squared distance from p to triangle t, exactly as the searches compute it.
  double triangle_distance2(Vec3d p, size_t t) const;

  // Appends to `out` every triangle whose box meets the box [lo, hi], in the tree's order.
  void overlapping(Vec3d lo, Vec3d hi, std::vector<uint32_t>& out) const;

  // The same for a group of nearby points (count <= kTreeGroup), bound2[k] updated in place and
  // start[k] required: after the start leaves, one walk down the tree collects the leaves near
  // the whole group (within each point's best distance so far), and each point tests only those;
  // a point that reaches `enough2` stops, and the walk stops when every point has.
  void nearest2_group(const Vec3d* p, double* bound2, const size_t* start, size_t count,
                      double enough2 = -1) const;

 private:
  struct Box {
    float lo[3], hi[3];
    static Box of(Vec3f a, Vec3f b, Vec3f c);  // a triangle's
    bool overlaps(const Box& o) const;
    void add(Vec3f v);
    void merge(const Box& o);
    double distance2(Vec3d p) const;  // a lower bound of the squared distance to the box
  };

  size_t leaf_begin(uint64_t leaf) const { return (leaf * n_) >> levels_; }
  // The leaf j with leaf_begin(j) <= t < leaf_begin(j + 1).
  uint64_t leaf_of(size_t t) const { return (((uint64_t{t} + 1) << levels_) + n_ - 1) / n_ - 1; }
  // The boxes of one leaf's triangles, made once for all the points of a group that test it.
  struct LeafBoxes;
  void leaf_boxes(uint64_t leaf, LeafBoxes& out) const;
  void test_leaf(Vec3d p, uint64_t leaf, double& best, double enough2,
                 size_t* nearest = nullptr, const LeafBoxes* boxes = nullptr) const;
  // Calls visit(leaf) for every leaf whose box meets `region`, in leaf order, until it returns
  // false.
  template <class Visit>
  void for_each_leaf_meeting(const Box& region, Visit&& visit) const;

  const Vec3f* pos_;
  const uint32_t* idx_;
  size_t n_;
  int levels_ = 0;
  std::vector<Box> boxes_;  // complete binary tree in heap order
};

// The triangles nearest to the last few points searched in a run of nearby points (samples in
// surface order), the most recent first, to bound and start the next search. A run of the
// extraction's samples alternates between the few places where a row crosses the surface, so one
// triangle is not enough: on make_big.py's bone, with one kept 16 % of the samples it could have
// skipped were searched, with eight 6 %.
class RecentTriangles {
 public:
  static constexpr size_t kKept = 8;

  // The least squared distance from p to a kept triangle (which then goes first), stopping at
  // the first at or below `enough2`; infinity when none is kept.
  double bound2(const OrderedTriangleTree& tree, Vec3d p, double enough2 = -1);
  // The first kept triangle, or kNoStart.
  size_t first() const { return kept_ > 0 ? triangle_[0] : OrderedTriangleTree::kNoStart; }
  // Puts t first; kNoStart is ignored.
  void add(size_t t);
  // tree.nearest2 from the first kept triangle below bound2 (best: the first's distance, as
  // bound2 leaves it), the triangle it finds put first.
  double search(const OrderedTriangleTree& tree, Vec3d p, double bound2, double enough2 = -1) {
    size_t found = first();
    const double d2 = tree.nearest2(p, bound2, found, enough2, &found);
    add(found);
    return d2;
  }

 private:
  std::array<size_t, kKept> triangle_{};
  size_t kept_ = 0;
};

// For each of nv vertices, the smallest id among the n triangles idx[3t..3t+2] that use it, or
// kNoTriangle when none does: where a search for a point near the vertex starts (the triangle's
// leaf). Parallel; the same for any thread count.
inline constexpr uint32_t kNoTriangle = std::numeric_limits<uint32_t>::max();
std::vector<uint32_t> first_triangles(const uint32_t* idx, size_t n, size_t nv);

// The n triangles idx[3t..3t+2] over pos as a new index array in the Morton order of their
// centroids (ties by triangle id): for a tree over a mesh whose own order is not compact in space
// (a decimated mesh, or one from a file). Parallel; the same for any thread count.
std::vector<uint32_t> morton_ordered_indices(const Vec3f* pos, const uint32_t* idx, size_t n);

}  // namespace segmesh
