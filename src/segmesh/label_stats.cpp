#include "segmesh/label_stats.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace segmesh {

template <class T>
std::vector<LabelCount> count_labels(const Volume<T>& volume) {
  using Counts = std::unordered_map<int32_t, int64_t>;
  const auto& v = volume.voxels;
  const Counts counts = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, v.size(), 1 << 16), Counts{},
      [&](const tbb::blocked_range<size_t>& r, Counts local) {
        // Label maps come in long runs of one value: count runs, not voxels, into the map.
        size_t i = r.begin();
        while (i < r.end()) {
          const int32_t label = v[i];
          size_t j = i + 1;
          while (j < r.end() && v[j] == label) ++j;
          local[label] += static_cast<int64_t>(j - i);
          i = j;
        }
        return local;
      },
      [](Counts a, const Counts& b) {
        for (const auto& [label, n] : b) a[label] += n;
        return a;
      });
  std::vector<LabelCount> out;
  out.reserve(counts.size());
  for (const auto& [label, n] : counts) out.push_back({label, n});
  std::sort(out.begin(), out.end(),
            [](const LabelCount& a, const LabelCount& b) { return a.label < b.label; });
  return out;
}

template <class T>
ValueRange value_range(const Volume<T>& volume) {
  struct Acc {
    double min = std::numeric_limits<double>::infinity();
    double max = -std::numeric_limits<double>::infinity();
    int64_t non_finite = 0;
  };
  const auto& v = volume.voxels;
  const Acc acc = tbb::parallel_reduce(
      tbb::blocked_range<size_t>(0, v.size(), 1 << 16), Acc{},
      [&](const tbb::blocked_range<size_t>& r, Acc a) {
        for (size_t i = r.begin(); i < r.end(); ++i) {
          const double x = static_cast<double>(v[i]);
          if (!std::isfinite(x)) {
            ++a.non_finite;
            continue;
          }
          a.min = std::min(a.min, x);
          a.max = std::max(a.max, x);
        }
        return a;
      },
      [](Acc a, const Acc& b) {
        a.min = std::min(a.min, b.min);
        a.max = std::max(a.max, b.max);
        a.non_finite += b.non_finite;
        return a;
      });
  if (acc.min > acc.max) return {0, 0, acc.non_finite};
  return {acc.min, acc.max, acc.non_finite};
}

template std::vector<LabelCount> count_labels(const Volume<uint8_t>&);
template std::vector<LabelCount> count_labels(const Volume<int16_t>&);
template std::vector<LabelCount> count_labels(const Volume<uint16_t>&);
template std::vector<LabelCount> count_labels(const Volume<int32_t>&);
template ValueRange value_range(const Volume<uint8_t>&);
template ValueRange value_range(const Volume<int16_t>&);
template ValueRange value_range(const Volume<uint16_t>&);
template ValueRange value_range(const Volume<int32_t>&);
template ValueRange value_range(const Volume<float>&);

}  // namespace segmesh
