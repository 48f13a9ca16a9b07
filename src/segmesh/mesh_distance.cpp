#include "segmesh/mesh_distance.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>
#include <optional>

#include "segmesh/detail/deviation_strata.hpp"
#include "segmesh/detail/ordered_triangle_tree.hpp"
#include "segmesh/moved_mesh_deviation.hpp"

namespace segmesh {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kInfF = std::numeric_limits<float>::infinity();

// sin^2 of the angle at the first corner below which a triangle is taken as its edges. There the
// triangle lies within 1e-8 of its size from its edges, and above it the region tests of the
// Voronoi method are accurate to about 1e-16 / 1e-8 of the size: the two errors balance.
constexpr double kFlatSin2 = 1e-16;

// Leaves hold 4 to 8 triangles: smaller leaves need twice the boxes for no gain, larger ones make
// every query test more triangles.
constexpr size_t kMaxLeafTriangles = 8;

// A box's squared distance is scaled by this before it is compared: the box axes are float
// vectors, orthonormal only to about 1e-7, so the distance measured along them can exceed the
// true one by that much relative (the Gram matrix's largest eigenvalue is below 1 + 1e-6).
constexpr double kBoxShrink = 1 - 1e-6;


double length2(Vec3d v) {
  return dot(v, v);
}

// t / d clamped to [0, 1]; 0 when d is not positive (only reachable by rounding on a triangle at
// the flatness limit, where any point of the feature is as good).
double fraction(double t, double d) {
  return d > 0 ? std::clamp(t / d, 0.0, 1.0) : 0.0;
}

}  // namespace

Vec3d closest_point_on_segment(Vec3d p, Vec3d a, Vec3d b) {
  const Vec3d ab = b - a;
  const double t = dot(p - a, ab);
  if (t <= 0) return a;
  const double len2 = length2(ab);
  if (t >= len2) return b;
  return a + (t / len2) * ab;
}

Vec3d closest_point_on_triangle(Vec3d p, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d ab = b - a, ac = c - a;
  const Vec3d n = cross(ab, ac);
  const double nn = length2(n);
  if (!(nn > kFlatSin2 * length2(ab) * length2(ac))) {
    // Collinear or repeated corners: the triangle is the union of its edges.
    const Vec3d q[3] = {closest_point_on_segment(p, a, b), closest_point_on_segment(p, b, c),
                        closest_point_on_segment(p, c, a)};
    int best = 0;
    for (int k = 1; k < 3; ++k)
      if (length2(p - q[k]) < length2(p - q[best])) best = k;
    return q[best];
  }
  // Ericson's region tests, in his notation.
  const Vec3d ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3d bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + fraction(d1, d1 - d3) * ab;
  const Vec3d cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + fraction(d2, d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return b + fraction(d4 - d3, (d4 - d3) + (d5 - d6)) * (c - b);
  }
  // Inside the face region: dropping the normal component keeps p's in-plane position exact,
  // where Ericson's barycentric combination would amplify the rounding of va, vb, vc.
  return p - (dot(ap, n) / nn) * n;
}

MeshDistance::MeshDistance(const TriMesh& mesh) {
  const size_t n = mesh.triangle_count();
  if (n == 0) return;
  const auto& pos = mesh.positions;
  const auto& idx = mesh.indices;
  while (((n - 1) >> levels_) + 1 > kMaxLeafTriangles) ++levels_;

  struct Item {
    float centroid[3];
    uint32_t triangle;
  };
  std::vector<Item> items(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      assert(idx[3 * t] < pos.size() && idx[3 * t + 1] < pos.size() && idx[3 * t + 2] < pos.size());
      const Vec3f& a = pos[idx[3 * t]];
      const Vec3f& b = pos[idx[3 * t + 1]];
      const Vec3f& c = pos[idx[3 * t + 2]];
      items[t] = {{(a.x + b.x + c.x) / 3, (a.y + b.y + c.y) / 3, (a.z + b.z + c.z) / 3},
                  static_cast<uint32_t>(t)};
    }
  });

  // Top-down median splits, one level at a time. Node k of depth d owns items
  // [k n / 2^d, (k+1) n / 2^d) (rounded down), so the ranges of a level are disjoint and known in
  // advance: the nodes of a level are partitioned in parallel and the result does not depend on
  // the schedule.
  for (int d = 0; d < levels_; ++d) {
    const uint64_t nodes = uint64_t{1} << d;
    tbb::parallel_for(
        tbb::blocked_range<uint64_t>(0, nodes, 1), [&](const tbb::blocked_range<uint64_t>& r) {
          for (uint64_t k = r.begin(); k != r.end(); ++k) {
            const size_t lo = (k * n) >> d, hi = ((k + 1) * n) >> d;
            const size_t mid = ((2 * k + 1) * n) >> (d + 1);
            float cmin[3] = {kInfF, kInfF, kInfF}, cmax[3] = {-kInfF, -kInfF, -kInfF};
            for (size_t i = lo; i < hi; ++i)
              for (int axis = 0; axis < 3; ++axis) {
                cmin[axis] = std::min(cmin[axis], items[i].centroid[axis]);
                cmax[axis] = std::max(cmax[axis], items[i].centroid[axis]);
              }
            int axis = 0;
            for (int a = 1; a < 3; ++a)
              if (cmax[a] - cmin[a] > cmax[axis] - cmin[axis]) axis = a;
            std::nth_element(items.begin() + lo, items.begin() + mid, items.begin() + hi,
                             [axis](const Item& x, const Item& y) {
                               return x.centroid[axis] < y.centroid[axis];
                             });
          }
        });
  }

  triangles_.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const size_t t = items[i].triangle;
      triangles_[i] = {pos[idx[3 * t]], pos[idx[3 * t + 1]], pos[idx[3 * t + 2]]};
    }
  });
  items = {};

  build_boxes();
}

void MeshDistance::build_boxes() {
  // First axis-aligned boxes and area vectors (sums of the triangles' cross products) bottom-up,
  // leaves from their triangles and inner nodes from their children; then each node gets an
  // oriented box in the frame of its mean normal when that box is smaller. On a smooth surface a
  // node's triangles lie in a slab as thin as the surface bends over the node, so the oriented box
  // bounds the distance far more tightly than an axis-aligned box, whose extent across the surface
  // is about the node's size, so queries away from the surface test far fewer triangles.
  const uint64_t leaves = uint64_t{1} << levels_;
  const uint64_t nodes = 2 * leaves - 1;
  struct Aligned {
    float lo[3], hi[3];
    Vec3d area;
  };
  std::vector<Aligned> aligned(nodes);
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, leaves),
                    [&](const tbb::blocked_range<uint64_t>& r) {
                      for (uint64_t j = r.begin(); j != r.end(); ++j) {
                        Aligned box{{kInfF, kInfF, kInfF}, {-kInfF, -kInfF, -kInfF}, {}};
                        for (size_t i = leaf_begin(j); i < leaf_begin(j + 1); ++i) {
                          const Triangle& t = triangles_[i];
                          for (const Vec3f& v : {t.a, t.b, t.c}) {
                            const float c[3] = {v.x, v.y, v.z};
                            for (int axis = 0; axis < 3; ++axis) {
                              box.lo[axis] = std::min(box.lo[axis], c[axis]);
                              box.hi[axis] = std::max(box.hi[axis], c[axis]);
                            }
                          }
                          const Vec3d a = to_double(t.a);
                          box.area = box.area + cross(to_double(t.b) - a, to_double(t.c) - a);
                        }
                        aligned[leaves - 1 + j] = box;
                      }
                    });
  for (int d = levels_ - 1; d >= 0; --d) {
    const uint64_t first = (uint64_t{1} << d) - 1, count = uint64_t{1} << d;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(first, first + count),
                      [&](const tbb::blocked_range<uint64_t>& r) {
                        for (uint64_t i = r.begin(); i != r.end(); ++i) {
                          const Aligned& l = aligned[2 * i + 1];
                          const Aligned& h = aligned[2 * i + 2];
                          for (int axis = 0; axis < 3; ++axis) {
                            aligned[i].lo[axis] = std::min(l.lo[axis], h.lo[axis]);
                            aligned[i].hi[axis] = std::max(l.hi[axis], h.hi[axis]);
                          }
                          aligned[i].area = l.area + h.area;
                        }
                      });
  }

  boxes_.resize(nodes);
  tbb::parallel_for(
      tbb::blocked_range<uint64_t>(0, nodes, 16), [&](const tbb::blocked_range<uint64_t>& r) {
        for (uint64_t i = r.begin(); i != r.end(); ++i) {
          const Aligned& a = aligned[i];
          Box& box = boxes_[i];
          box = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                 {a.lo[0], a.lo[1], a.lo[2]},
                 {a.hi[0], a.hi[1], a.hi[2]}};
          const double area = norm(a.area);
          if (!(area > 0)) continue;  // only degenerate triangles, or normals cancelling exactly
          // Frame: the mean normal, and the world axis least aligned with it made orthogonal.
          const Vec3d n = (1 / area) * a.area;
          const double ax = std::abs(n.x), ay = std::abs(n.y), az = std::abs(n.z);
          const Vec3d e = ax <= ay && ax <= az ? Vec3d{1, 0, 0}
                          : ay <= az           ? Vec3d{0, 1, 0}
                                               : Vec3d{0, 0, 1};
          const Vec3d u = cross(n, e);
          const Vec3d frame[3] = {n, (1 / norm(u)) * u, (1 / norm(u)) * cross(n, u)};
          Box oriented;
          Vec3d axes[3];
          for (int k = 0; k < 3; ++k) {
            const Vec3f f = to_float(frame[k]);
            oriented.axis[k][0] = f.x;
            oriented.axis[k][1] = f.y;
            oriented.axis[k][2] = f.z;
            axes[k] = to_double(f);  // project with the float axes the queries will use
          }
          double lo[3] = {kInf, kInf, kInf}, hi[3] = {-kInf, -kInf, -kInf};
          const int depth = std::bit_width(i + 1) - 1;
          const uint64_t k = i + 1 - (uint64_t{1} << depth);
          const size_t begin = (k * triangles_.size()) >> depth;
          const size_t end = ((k + 1) * triangles_.size()) >> depth;
          for (size_t t = begin; t < end; ++t)
            for (const Vec3f& v : {triangles_[t].a, triangles_[t].b, triangles_[t].c}) {
              const Vec3d x = to_double(v);
              for (int axis = 0; axis < 3; ++axis) {
                const double s = dot(axes[axis], x);
                lo[axis] = std::min(lo[axis], s);
                hi[axis] = std::max(hi[axis], s);
              }
            }
          double oriented_volume = 1, aligned_volume = 1;
          for (int axis = 0; axis < 3; ++axis) {
            // Rounded outwards, so the float box still contains every corner.
            oriented.lo[axis] = std::nextafter(static_cast<float>(lo[axis]), -kInfF);
            oriented.hi[axis] = std::nextafter(static_cast<float>(hi[axis]), kInfF);
            oriented_volume *= double(oriented.hi[axis]) - double(oriented.lo[axis]);
            aligned_volume *= double(a.hi[axis]) - double(a.lo[axis]);
          }
          if (oriented_volume < aligned_volume) box = oriented;
        }
      });
}

MeshDistance::Hit MeshDistance::nearest(Vec3d p, double bound2) const {
  Hit best{{kInf, kInf, kInf}, bound2};
  if (triangles_.empty()) return best;
  const double q[3] = {p.x, p.y, p.z};
  auto box_distance2 = [&](uint64_t node) {
    const Box& b = boxes_[node];
    double d2 = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const double s = double(b.axis[axis][0]) * q[0] + double(b.axis[axis][1]) * q[1] +
                       double(b.axis[axis][2]) * q[2];
      const double d = std::max({double(b.lo[axis]) - s, s - double(b.hi[axis]), 0.0});
      d2 += d * d;
    }
    return d2 * kBoxShrink;
  };

  struct Entry {
    uint64_t node;
    double distance2;
  };
  // A pop pushes at most two children, so the stack never holds more than depth + 1 entries.
  Entry stack[64];
  int top = 0;
  stack[top++] = {0, box_distance2(0)};
  const uint64_t first_leaf = (uint64_t{1} << levels_) - 1;
  while (top > 0) {
    const Entry e = stack[--top];
    // The best distance may have shrunk since this node was pushed.
    if (!(e.distance2 < best.distance2)) continue;
    if (e.node >= first_leaf) {
      const uint64_t leaf = e.node - first_leaf;
      for (size_t i = leaf_begin(leaf), end = leaf_begin(leaf + 1); i < end; ++i) {
        const Triangle& t = triangles_[i];
        const Vec3d c =
            closest_point_on_triangle(p, to_double(t.a), to_double(t.b), to_double(t.c));
        const double d2 = length2(p - c);
        if (d2 < best.distance2) best = {c, d2};
      }
      continue;
    }
    Entry near{2 * e.node + 1, box_distance2(2 * e.node + 1)};
    Entry far{2 * e.node + 2, box_distance2(2 * e.node + 2)};
    if (far.distance2 < near.distance2) std::swap(near, far);
    // Nearer child on top: it is searched first and usually shrinks the bound that prunes the
    // other.
    if (far.distance2 < best.distance2) stack[top++] = far;
    if (near.distance2 < best.distance2) stack[top++] = near;
  }
  return best;
}

double MeshDistance::distance(Vec3d p) const {
  return std::sqrt(nearest(p).distance2);
}

double MeshDistance::distance(Vec3d p, double upper_bound) const {
  return std::sqrt(nearest(p, upper_bound * upper_bound).distance2);
}

Vec3d MeshDistance::closest_point(Vec3d p) const {
  return nearest(p).point;
}

namespace {

// The samples of one direction: mesh `from`'s vertices used by a triangle (sample v < vertex
// count) and its triangles' centroids (sample vertex count + t), measured against `to`'s tree.
struct DirectionSamples {
  const TriMesh& from;
  const OrderedTriangleTree& to;
  std::vector<char> used;

  DirectionSamples(const TriMesh& mesh, const OrderedTriangleTree& target)
      : from(mesh), to(target), used(mesh.positions.size(), 0) {
    for (uint32_t v : mesh.indices) used[v] = 1;
  }
  size_t count() const { return from.positions.size() + from.triangle_count(); }
  // Sample s's point; false for a vertex no triangle uses.
  bool get(size_t s, Vec3d& p) const {
    const size_t nv = from.positions.size();
    if (s < nv) {
      if (!used[s]) return false;
      p = to_double(from.positions[s]);
      return true;
    }
    const uint32_t* x = &from.indices[3 * (s - nv)];
    p = (1.0 / 3.0) * (to_double(from.positions[x[0]]) + to_double(from.positions[x[1]]) +
                       to_double(from.positions[x[2]]));
    return true;
  }
};

// The chosen samples of one direction (stratum_chosen), each measured exactly, each search
// bounded and started by the block's recent nearest triangles.
SampleDistances measure_chosen(const DirectionSamples& samples, size_t stride) {
  return measure_in_blocks(samples.count(), [&](size_t begin, size_t end, std::vector<double>& out) {
    RecentTriangles recent;
    for_each_chosen(begin, end, stride, [&](size_t s) {
      Vec3d p;
      if (samples.get(s, p))
        out.push_back(std::sqrt(recent.search(samples.to, p, recent.bound2(samples.to, p))));
    });
  });
}

// The largest distance of the samples not chosen, or `largest` when none exceeds it: a sample
// whose distance to the last nearest triangle is at or below the largest so far cannot raise it,
// and a search for one that might stops at the first triangle within it.
double largest_unchosen(const DirectionSamples& samples, size_t stride, double largest) {
  const size_t n = samples.count();
  const size_t blocks = (n + kDeviationSampleBlock - 1) / kDeviationSampleBlock;
  std::vector<double> block_max(blocks, largest);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t b = r.begin(); b != r.end(); ++b) {
      RecentTriangles recent;
      double max2 = largest * largest;
      for (size_t s = b * kDeviationSampleBlock, end = std::min(n, (b + 1) * kDeviationSampleBlock);
           s < end; ++s) {
        Vec3d p;
        if (stratum_chosen(s, stride) || !samples.get(s, p)) continue;
        const double bound2 = recent.bound2(samples.to, p, max2);
        if (bound2 <= max2) continue;
        max2 = std::max(max2, recent.search(samples.to, p, bound2, max2));
      }
      block_max[b] = std::sqrt(max2);
    }
  });
  for (double d : block_max) largest = std::max(largest, d);
  return largest;
}

}  // namespace

Deviation mesh_deviation(const TriMesh& a, const TriMesh& b) {
  if (a.empty() && b.empty()) return {0, 0, 0};
  if (a.empty() || b.empty()) return {kInf, kInf, kInf};
  // A mesh and its moved copy: each search bounded by the sample's counterpart.
  if (a.positions.size() == b.positions.size() && a.indices == b.indices) {
    return moved_mesh_deviation(a.positions, b, std::numeric_limits<size_t>::max());
  }
  // Each tree on its mesh's triangles in Morton order when that mesh has no more triangles than
  // the other (whose samples it serves, three or so per triangle), else in the mesh's own order:
  // sorting a mesh many times larger than the samples it serves costs more than its searches.
  std::vector<uint32_t> order_a, order_b;
  std::optional<OrderedTriangleTree> tree_a, tree_b;
  auto build = [](const TriMesh& m, size_t other, std::vector<uint32_t>& order,
                  std::optional<OrderedTriangleTree>& tree) {
    const size_t n = m.triangle_count();
    if (n <= other) order = morton_ordered_indices(m.positions.data(), m.indices.data(), n);
    tree.emplace(m.positions.data(), order.empty() ? m.indices.data() : order.data(), n);
  };
  tbb::parallel_invoke([&] { build(a, b.triangle_count(), order_a, tree_a); },
                       [&] { build(b, a.triangle_count(), order_b, tree_b); });
  const DirectionSamples ab(a, *tree_b), ba(b, *tree_a);
  // One stride for both directions, so that the chosen samples keep the directions' proportions
  // and pool without weights (moved_mesh_deviation's choice when both have the same count).
  const size_t stride = stratum_stride(ab.count() + ba.count(), 2 * kDeviationStatisticSamples);
  SampleDistances sab = measure_chosen(ab, stride);
  SampleDistances sba = measure_chosen(ba, stride);
  double hausdorff = std::max(sab.max, sba.max);
  if (stride > 1) {
    hausdorff = largest_unchosen(ab, stride, hausdorff);
    hausdorff = largest_unchosen(ba, stride, hausdorff);
  }
  return pooled_deviation(std::move(sab), std::move(sba), hausdorff);
}

}  // namespace segmesh
