#include "segmesh/detail/ordered_triangle_tree.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "segmesh/detail/morton.hpp"
#include "segmesh/mesh_distance.hpp"

namespace segmesh {

namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();

// Consecutive triangles per leaf: fewer leaves mean less tree to store and walk, more triangles
// per leaf more exact tests per search; 16 measured fastest on the phantom and make_big.py's map.
constexpr size_t kOrderedLeaf = 16;

// A box's squared distance is scaled by this before it is compared: the box bounds are exact
// (minima and maxima of the float corners), so only the rounding of the double sums matters.
constexpr double kBoxShrink = 1 - 1e-12;

}  // namespace

bool OrderedTriangleTree::Box::overlaps(const Box& o) const {
  for (int a = 0; a < 3; ++a)
    if (lo[a] > o.hi[a] || o.lo[a] > hi[a]) return false;
  return true;
}

void OrderedTriangleTree::Box::add(Vec3f v) {
  const float c[3] = {v.x, v.y, v.z};
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min(lo[a], c[a]);
    hi[a] = std::max(hi[a], c[a]);
  }
}

void OrderedTriangleTree::Box::merge(const Box& o) {
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::min(lo[a], o.lo[a]);
    hi[a] = std::max(hi[a], o.hi[a]);
  }
}

namespace {

// A lower bound of the squared distance from p to the box [lo, hi] (float or double bounds).
template <class T>
inline double box_distance2(const T* lo, const T* hi, Vec3d p) {
  const double q[3] = {p.x, p.y, p.z};
  double d2 = 0;
  for (int a = 0; a < 3; ++a) {
    const double d = std::max({double(lo[a]) - q[a], q[a] - double(hi[a]), 0.0});
    d2 += d * d;
  }
  return d2 * kBoxShrink;
}

}  // namespace

OrderedTriangleTree::Box OrderedTriangleTree::Box::of(Vec3f a, Vec3f b, Vec3f c) {
  Box box{{a.x, a.y, a.z}, {a.x, a.y, a.z}};
  box.add(b);
  box.add(c);
  return box;
}

double OrderedTriangleTree::Box::distance2(Vec3d p) const {
  return box_distance2(lo, hi, p);
}

OrderedTriangleTree::OrderedTriangleTree(const Vec3f* pos, const uint32_t* idx, size_t n)
    : pos_(pos), idx_(idx), n_(n) {
  while (((n_ - 1) >> levels_) + 1 > kOrderedLeaf) ++levels_;
  const uint64_t leaves = uint64_t{1} << levels_;
  boxes_.resize(2 * leaves - 1);
  const uint64_t first = leaves - 1;
  tbb::parallel_for(tbb::blocked_range<uint64_t>(0, leaves),
                    [&](const tbb::blocked_range<uint64_t>& r) {
                      for (uint64_t j = r.begin(); j != r.end(); ++j) {
                        Box b{{kInfF, kInfF, kInfF}, {-kInfF, -kInfF, -kInfF}};
                        for (size_t t = leaf_begin(j); t < leaf_begin(j + 1); ++t)
                          for (int k = 0; k < 3; ++k) b.add(pos_[idx_[3 * t + k]]);
                        boxes_[first + j] = b;
                      }
                    });
  for (int d = levels_ - 1; d >= 0; --d) {
    const uint64_t begin = (uint64_t{1} << d) - 1, end = (uint64_t{2} << d) - 1;
    tbb::parallel_for(tbb::blocked_range<uint64_t>(begin, end, 1024),
                      [&](const tbb::blocked_range<uint64_t>& r) {
                        for (uint64_t i = r.begin(); i != r.end(); ++i) {
                          Box b = boxes_[2 * i + 1];
                          b.merge(boxes_[2 * i + 2]);
                          boxes_[i] = b;
                        }
                      });
  }
}

// In double, converted once for all the points that test them; distance2 as Box::distance2.
struct OrderedTriangleTree::LeafBoxes {
  struct Double {
    double lo[3], hi[3];
    double distance2(Vec3d p) const { return box_distance2(lo, hi, p); }
  };
  Double box[kOrderedLeaf];
};

void OrderedTriangleTree::leaf_boxes(uint64_t leaf, LeafBoxes& out) const {
  for (size_t t = leaf_begin(leaf), end = leaf_begin(leaf + 1), k = 0; t < end; ++t, ++k) {
    const Box box = Box::of(pos_[idx_[3 * t]], pos_[idx_[3 * t + 1]], pos_[idx_[3 * t + 2]]);
    for (int a = 0; a < 3; ++a) {
      out.box[k].lo[a] = double(box.lo[a]);
      out.box[k].hi[a] = double(box.hi[a]);
    }
  }
}

// Each triangle's own box is tried first: most triangles of a leaf are farther than the best
// distance, and the box rejects them at a fraction of the exact test's cost. A caller that only
// asks whether the distance is at most `enough2` is answered by the first corner or triangle
// that close: the rest of the leaf is skipped. With `boxes` (the leaf's, from leaf_boxes), the
// boxes are read instead of made: the same boxes, the same answer.
void OrderedTriangleTree::test_leaf(Vec3d p, uint64_t leaf, double& best, double enough2,
                                    size_t* nearest, const LeafBoxes* boxes) const {
  const size_t begin = leaf_begin(leaf);
  for (size_t t = begin, end = leaf_begin(leaf + 1); t < end; ++t) {
    if (boxes && !(boxes->box[t - begin].distance2(p) < best)) continue;
    const Vec3f fa = pos_[idx_[3 * t]], fb = pos_[idx_[3 * t + 1]], fc = pos_[idx_[3 * t + 2]];
    if (!boxes && !(Box::of(fa, fb, fc).distance2(p) < best)) continue;
    const Vec3d a = to_double(fa), b = to_double(fb), c = to_double(fc);
    if (enough2 >= 0) {
      const double corner = nearest_corner_distance2(p, a, b, c);
      if (corner <= enough2) {
        if (corner < best) {
          best = corner;
          if (nearest) *nearest = t;
        }
        return;
      }
    }
    const double d2 = point_triangle_distance2(p, a, b, c);
    if (d2 < best) {
      best = d2;
      if (nearest) *nearest = t;
    }
    if (best <= enough2) return;
  }
}

double OrderedTriangleTree::triangle_distance2(Vec3d p, size_t t) const {
  return point_triangle_distance2(p, to_double(pos_[idx_[3 * t]]), to_double(pos_[idx_[3 * t + 1]]),
                               to_double(pos_[idx_[3 * t + 2]]));
}

template <class Visit>
void OrderedTriangleTree::for_each_leaf_meeting(const Box& region, Visit&& visit) const {
  const uint64_t first = (uint64_t{1} << levels_) - 1;
  uint64_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const uint64_t node = stack[--top];
    if (!boxes_[node].overlaps(region)) continue;
    if (node < first) {  // the right child below the left, so leaves come in order
      stack[top++] = 2 * node + 2;
      stack[top++] = 2 * node + 1;
      continue;
    }
    if (!visit(node - first)) return;
  }
}

void OrderedTriangleTree::overlapping(Vec3d lo, Vec3d hi, std::vector<uint32_t>& out) const {
  // The query box rounded outwards to float, so no box that meets it in double is missed.
  const Box query{{std::nextafter(float(lo.x), -kInfF), std::nextafter(float(lo.y), -kInfF),
                   std::nextafter(float(lo.z), -kInfF)},
                  {std::nextafter(float(hi.x), kInfF), std::nextafter(float(hi.y), kInfF),
                   std::nextafter(float(hi.z), kInfF)}};
  for_each_leaf_meeting(query, [&](uint64_t leaf) {
    for (size_t t = leaf_begin(leaf), end = leaf_begin(leaf + 1); t < end; ++t) {
      if (Box::of(pos_[idx_[3 * t]], pos_[idx_[3 * t + 1]], pos_[idx_[3 * t + 2]]).overlaps(query))
        out.push_back(uint32_t(t));
    }
    return true;
  });
}

double OrderedTriangleTree::nearest2(Vec3d p, double bound2, size_t start, double enough2,
                                     size_t* nearest) const {
  double best = bound2;
  const uint64_t first = (uint64_t{1} << levels_) - 1;
  struct Entry {
    uint64_t node;
    double distance2;
  };
  Entry stack[64];
  // The subtree under `root`, nearer child first, pruned by the best distance so far; true when
  // a caller asking about enough2 has its answer.
  auto search = [&](uint64_t root, double root_distance2) {
    int top = 0;
    stack[top++] = {root, root_distance2};
    while (top > 0) {
      const Entry e = stack[--top];
      if (!(e.distance2 < best)) continue;
      if (e.node >= first) {
        test_leaf(p, e.node - first, best, enough2, nearest);
        if (best <= enough2) return true;
        continue;
      }
      Entry near{2 * e.node + 1, boxes_[2 * e.node + 1].distance2(p)};
      Entry far{2 * e.node + 2, boxes_[2 * e.node + 2].distance2(p)};
      if (far.distance2 < near.distance2) std::swap(near, far);
      // Nearer child on top: it is searched first and usually shrinks the bound that prunes the
      // other.
      if (far.distance2 < best) stack[top++] = far;
      if (near.distance2 < best) stack[top++] = near;
    }
    return false;
  };
  if (start == kNoStart) {
    search(0, boxes_[0].distance2(p));
    return best;
  }
  // From the start leaf up: at every level the sibling subtree, when its box is nearer than the
  // best distance so far. The closest triangle is usually in or near the start leaf, so most
  // levels cost one box test, where a walk from the root tests two boxes a level on the way down
  // and more beside it.
  uint64_t node = first + leaf_of(start);
  test_leaf(p, node - first, best, enough2, nearest);
  if (best <= enough2) return best;
  while (node > 0) {
    const uint64_t sibling = (node & 1) ? node + 1 : node - 1;
    const double d2 = boxes_[sibling].distance2(p);
    if (d2 < best && search(sibling, d2)) return best;
    node = (node - 1) / 2;
  }
  return best;
}

void OrderedTriangleTree::nearest2_group(const Vec3d* p, double* bound2, const size_t* start,
                                         size_t count, double enough2) const {
  uint64_t start_leaf[kTreeGroup];
  bool active[kTreeGroup];
  bool any = false;
  Box region{{kInfF, kInfF, kInfF}, {-kInfF, -kInfF, -kInfF}};
  // Neighbouring points often start in the same leaf: its boxes are made once.
  LeafBoxes boxes;
  uint64_t boxes_leaf = ~uint64_t{0};
  for (size_t k = 0; k < count; ++k) {
    start_leaf[k] = leaf_of(start[k]);
    if (start_leaf[k] != boxes_leaf) leaf_boxes(boxes_leaf = start_leaf[k], boxes);
    test_leaf(p[k], start_leaf[k], bound2[k], enough2, nullptr, &boxes);
    active[k] = bound2[k] > enough2;
    if (!active[k]) continue;
    any = true;
    // The region holds every point's ball of its best distance (rounded outwards).
    const double r = std::sqrt(bound2[k]) * (1 + 1e-9);
    const double c[3] = {p[k].x, p[k].y, p[k].z};
    for (int a = 0; a < 3; ++a) {
      // Widened by a millionth before rounding to float (whose rounding is below 1e-7
      // relative), so the float bounds hold the ball.
      const double lo = c[a] - r, hi = c[a] + r;
      region.lo[a] = std::min(region.lo[a], float(lo - 1e-6 * std::abs(lo) - 1e-30));
      region.hi[a] = std::max(region.hi[a], float(hi + 1e-6 * std::abs(hi) + 1e-30));
    }
  }
  if (!any) return;
  for_each_leaf_meeting(region, [&](uint64_t leaf) {
    const Box& nb = boxes_[(uint64_t{1} << levels_) - 1 + leaf];
    const double lo[3] = {nb.lo[0], nb.lo[1], nb.lo[2]}, hi[3] = {nb.hi[0], nb.hi[1], nb.hi[2]};
    bool left = false;
    for (size_t k = 0; k < count; ++k) {
      if (active[k] && leaf != start_leaf[k] && box_distance2(lo, hi, p[k]) < bound2[k]) {
        if (leaf != boxes_leaf) leaf_boxes(boxes_leaf = leaf, boxes);
        test_leaf(p[k], leaf, bound2[k], enough2, nullptr, &boxes);
        active[k] = bound2[k] > enough2;
      }
      left = left || active[k];
    }
    return left;
  });
}

double RecentTriangles::bound2(const OrderedTriangleTree& tree, Vec3d p, double enough2) {
  double best = std::numeric_limits<double>::infinity();
  size_t at = 0;
  for (size_t k = 0; k < kept_; ++k) {
    const double d2 = tree.triangle_distance2(p, triangle_[k]);
    if (d2 < best) {
      best = d2;
      at = k;
    }
    if (best <= enough2) break;
  }
  if (at > 0) std::rotate(triangle_.begin(), triangle_.begin() + at, triangle_.begin() + at + 1);
  return best;
}

void RecentTriangles::add(size_t t) {
  if (t == OrderedTriangleTree::kNoStart || (kept_ > 0 && triangle_[0] == t)) return;
  const size_t at = size_t(std::find(triangle_.begin(), triangle_.begin() + kept_, t) - triangle_.begin());
  if (at == kept_) kept_ = std::min(kept_ + 1, kKept);
  const size_t last = std::min(at, kKept - 1);
  std::rotate(triangle_.begin(), triangle_.begin() + last, triangle_.begin() + last + 1);
  triangle_[0] = t;
}

std::vector<uint32_t> first_triangles(const uint32_t* idx, size_t n, size_t nv) {
  std::vector<uint32_t> first(nv, kNoTriangle);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t)
      for (int k = 0; k < 3; ++k) {
        std::atomic_ref<uint32_t> slot(first[idx[3 * t + size_t(k)]]);
        uint32_t seen = slot.load(std::memory_order_relaxed);
        while (t < seen &&
               !slot.compare_exchange_weak(seen, uint32_t(t), std::memory_order_relaxed)) {
        }
      }
  });
  return first;
}

std::vector<uint32_t> morton_ordered_indices(const Vec3f* pos, const uint32_t* idx, size_t n) {
  auto centroid = [&](size_t t) {
    return to_double(pos[idx[3 * t]]) + to_double(pos[idx[3 * t + 1]]) + to_double(pos[idx[3 * t + 2]]);
  };  // three times the centroid
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Vec3d lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  for (size_t t = 0; t < n; ++t) {
    const Vec3d c = centroid(t);
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  // One scale for all three axes (cubic cells), 2^21 cells along the longest.
  const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const double scale = extent > 0 ? double((1 << 21) - 1) / extent : 0.0;
  auto cell = [&](double c, double l) {
    return std::clamp<int64_t>(int64_t((c - l) * scale), 0, (1 << 21) - 1);
  };
  struct Keyed {
    uint64_t key;
    uint32_t t;
    bool operator<(const Keyed& o) const { return key != o.key ? key < o.key : t < o.t; }
  };
  std::vector<Keyed> keyed(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t t = r.begin(); t != r.end(); ++t) {
      const Vec3d c = centroid(t);
      keyed[t] = {morton(cell(c.x, lo.x), cell(c.y, lo.y), cell(c.z, lo.z)), uint32_t(t)};
    }
  });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> out(3 * n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t k = r.begin(); k != r.end(); ++k)
      for (int c = 0; c < 3; ++c) out[3 * k + size_t(c)] = idx[3 * size_t(keyed[k].t) + size_t(c)];
  });
  return out;
}

}  // namespace segmesh
