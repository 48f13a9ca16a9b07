// The order and placement of decimation's collapses (decimation.cpp): a candidate collapse, the
// cost buckets that order them cheapest first, and where a collapse puts the merged vertex.
// Internal to the core: included by decimation.cpp only.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

#include "segmesh/detail/quadric.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

struct Candidate {
  double cost = 0;
  uint32_t remove = 0, keep = 0;
  Vec3d position;
  uint32_t remove_version = 0, keep_version = 0;
  // The heap's order: least cost first, ties by ids.
  bool operator<(const Candidate& o) const {
    if (cost != o.cost) return cost > o.cost;
    if (remove != o.remove) return remove > o.remove;
    return keep > o.keep;
  }
};

// The candidates by cost, cheapest first, in buckets 1/16 of an octave wide (4.4 %): a bucket is
// the top 16 bits of the cost's double (sign, exponent, 4 bits of mantissa), which order positive
// doubles as the doubles do. Costs at or below 2^-40 mm share the first bucket, above 2^24 the
// last. Within a bucket the last pushed comes first: the collapses near the last one, whose
// vertices are still in cache. A binary heap of the ~4 M candidates a million-triangle surface
// pushes spent more than half of the decimation in cache misses; pushing and popping here touch
// the ends of short arrays. Deterministic: the order depends only on the pushes.
class CostBuckets {
 public:
  CostBuckets() : buckets_(bucket(std::numeric_limits<double>::infinity()) + 1) {}
  bool empty() {
    while (first_ < buckets_.size() && buckets_[first_].empty()) ++first_;
    return first_ == buckets_.size();
  }
  void push(const Candidate& c) {
    const size_t b = bucket(c.cost);
    buckets_[b].push_back(c);
    first_ = std::min(first_, b);
  }
  // The cheapest bucket's last candidate, removed; call only when !empty().
  Candidate pop() {
    Candidate c = buckets_[first_].back();
    buckets_[first_].pop_back();
    return c;
  }
  static size_t bucket(double cost) {
    constexpr double lowest = 0x1p-40, highest = 0x1p24;
    const uint64_t base = std::bit_cast<uint64_t>(lowest) >> 48;
    if (!(cost > lowest)) return 0;
    return size_t((std::bit_cast<uint64_t>(std::min(cost, highest)) >> 48) - base);
  }
  static size_t bucket_count() { return bucket(std::numeric_limits<double>::infinity()) + 1; }

 private:
  std::vector<std::vector<Candidate>> buckets_;
  size_t first_ = 0;
};

// The placements. On a curve: the quadric's minimum on the segment between the two ends.
inline Vec3d best_on_segment(const Quadric& q, Vec3d a, Vec3d b) {
  // Q(a + t (b - a)) = A t^2 + B t + C; the minimum on [0, 1] or an end.
  const double q0 = evaluate(q, a), q1 = evaluate(q, b), qh = evaluate(q, 0.5 * (a + b));
  const double A = 2 * (q0 + q1) - 4 * qh, B = q1 - q0 - A;
  double t = q0 <= q1 ? 0 : 1;
  if (A > 0) {
    const double s = std::clamp(-B / (2 * A), 0.0, 1.0);
    if (evaluate(q, a + s * (b - a)) < std::min(q0, q1)) t = s;
  }
  return a + t * (b - a);
}

inline Vec3d best_free(const Quadric& q, Vec3d a, Vec3d b) {
  const Vec3d mid = 0.5 * (a + b);
  if (const auto x = optimum(q); x && norm(*x - mid) <= norm(b - a)) return *x;
  Vec3d best = mid;
  for (Vec3d p : {a, b})
    if (evaluate(q, p) < evaluate(q, best)) best = p;
  return best;
}

}  // namespace segmesh
