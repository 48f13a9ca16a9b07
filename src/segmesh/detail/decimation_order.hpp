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
// the top 16 bits of the cost's double (sign, exponent, 4 bits of mantissa), which order
// positive doubles as the doubles do. Costs at or below 2^-40 mm share the first bucket, above
// 2^24 the last. A binary heap of the ~4 M candidates a million-triangle surface pushes spent
// more than half of the decimation in cache misses; pushing and popping here touch the ends of
// short arrays.
//
// A bucket is put in vertex order when it is first reached (the candidates no longer current
// dropped, by `current`): a bucket holds candidates from all over the surface, and taken in
// vertex order they touch memory in the order the surface is stored, so their vertices,
// triangles and lists come from cache or the next lines instead of a miss each. Candidates
// pushed into it afterwards come first, the last pushed first: the collapses next to the last
// one, still in cache. Unless `exact` says the order within the octave matters (a budget may
// stop there: the collapses it leaves must be the dearest), the bucket first takes in the rest
// of its octave, so one sweep in vertex order covers the octave: denser sweeps, half the time
// of sweeps 1/16 of an octave wide at 0.2 mm on the phantom, for a result of the same size and
// error (docs/DECIMATION.md); a budget's last octave in vertex order measured 0.28 mm against
// 0.19 at 50 000 triangles, hence the exception. Deterministic: the order depends only on the
// pushes.
class CostBuckets {
 public:
  CostBuckets()
      : buckets_(bucket(std::numeric_limits<double>::infinity()) + 1), sorted_(buckets_.size()) {}
  // The next candidate, cheapest bucket first; false when none is left. `current(c)`: whether
  // c is still worth taking; `exact(upper_cost, count)`: whether the order within an octave of
  // `count` candidates of costs below `upper_cost` matters; `ahead(c)`: prefetches what
  // `current(c)` reads (nothing when not given).
  template <class Current, class Exact>
  bool pop(Candidate& out, Current&& current, Exact&& exact) {
    return pop(out, current, exact, [](const Candidate&) {});
  }
  // With `through`, only from the buckets up to that one (false when they are empty).
  template <class Current, class Exact, class Ahead>
  bool pop(Candidate& out, Current&& current, Exact&& exact, Ahead&& ahead,
           size_t through = std::numeric_limits<size_t>::max()) {
    while (first_ < buckets_.size()) {
      std::vector<Candidate>& b = buckets_[first_];
      if (b.empty()) {
        ++first_;
        continue;
      }
      if (first_ > through) return false;
      if (!sorted_[first_]) {
        sorted_[first_] = 1;
        const size_t octave_end = std::min(buckets_.size(), (first_ / kPerOctave + 1) * kPerOctave);
        size_t count = 0;
        for (size_t k = first_; k < octave_end; ++k) count += buckets_[k].size();
        if (!exact(upper_cost(octave_end - 1), count))
          for (size_t k = first_ + 1; k < octave_end; ++k) {
            b.insert(b.end(), buckets_[k].begin(), buckets_[k].end());
            buckets_[k].clear();
          }
        // The stale dropped in place, `ahead` asked for a later candidate's data first: the
        // checks read memory from all over the surface.
        size_t kept = 0;
        for (size_t k = 0; k < b.size(); ++k) {
          if (k + kAheadOfCheck < b.size()) ahead(b[k + kAheadOfCheck]);
          if (current(b[k])) b[kept++] = b[k];
        }
        b.resize(kept);
        // Descending, so that the back, taken first, is the lowest vertex.
        std::sort(b.begin(), b.end(), [](const Candidate& x, const Candidate& y) {
          if (x.keep != y.keep) return x.keep > y.keep;
          if (x.remove != y.remove) return x.remove > y.remove;
          return x.cost > y.cost;
        });
        continue;
      }
      out = b.back();
      b.pop_back();
      return true;
    }
    return false;
  }
  // The candidate that pops `ahead` pops after the next (0: the next), if no push comes between
  // and the current bucket holds it; nullptr otherwise. For prefetching.
  const Candidate* peek(size_t ahead) const {
    if (first_ >= buckets_.size() || !sorted_[first_]) return nullptr;
    const std::vector<Candidate>& b = buckets_[first_];
    return ahead < b.size() ? &b[b.size() - 1 - ahead] : nullptr;
  }
  // The first bucket holding candidates (current or not), bucket_count() when none does.
  size_t next_bucket() const {
    size_t b = first_;
    while (b < buckets_.size() && buckets_[b].empty()) ++b;
    return b;
  }
  void push(const Candidate& c) {
    const size_t b = bucket(c.cost);
    buckets_[b].push_back(c);
    first_ = std::min(first_, b);
  }
  static size_t bucket(double cost) {
    if (!(cost > kLowest)) return 0;
    return size_t((std::bit_cast<uint64_t>(std::min(cost, kHighest)) >> kShift) - base());
  }
  static size_t bucket_count() { return bucket(std::numeric_limits<double>::infinity()) + 1; }
  // The least cost above bucket b's.
  static double upper_cost(size_t b) { return std::bit_cast<double>((b + 1 + base()) << kShift); }

 private:
  static constexpr int kShift = 48;
  static constexpr size_t kAheadOfCheck = 16;
  static constexpr size_t kPerOctave = 16;
  static constexpr double kLowest = 0x1p-40, kHighest = 0x1p24;  // an octave's first bucket
  static uint64_t base() { return std::bit_cast<uint64_t>(kLowest) >> kShift; }
  std::vector<std::vector<Candidate>> buckets_;
  std::vector<char> sorted_;  // put in vertex order (reached once)
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
