// The merge of sorted run lists: on small hand-made rows, the intervals it visits and the state of
// every row on each, with one bit per row and with a value per row; adjacent runs of different
// values, empty rows, runs at the ends of the domain, and an offset between run and local x.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "segmesh/detail/run_merge.hpp"

namespace segmesh {
namespace {

struct ValueRun {
  int32_t x_begin = 0, x_end = 0;
  uint32_t value = 0;
};

template <size_t N>
struct Interval {
  int64_t s = 0, t = 0;
  std::array<uint32_t, N> values{};
  bool operator==(const Interval&) const = default;
};

template <size_t N>
std::vector<Interval<N>> value_intervals(int64_t nx, int64_t x0,
                                         const std::array<std::span<const ValueRun>, N>& rows) {
  std::vector<Interval<N>> out;
  merge_runs<RunValues<N, &ValueRun::value>>(nx, x0, rows,
                                             [&](int64_t s, int64_t t, const auto& state) {
                                               out.push_back({s, t, state.value});
                                             });
  return out;
}

template <size_t N>
std::vector<Interval<N>> bit_intervals(int64_t nx, int64_t x0,
                                       const std::array<std::span<const ValueRun>, N>& rows) {
  std::vector<Interval<N>> out;
  merge_runs<RowBits>(nx, x0, rows, [&](int64_t s, int64_t t, const RowBits& state) {
    Interval<N> v{s, t, {}};
    for (size_t n = 0; n < N; ++n) v.values[n] = state.bits >> n & 1u;
    out.push_back(v);
  });
  return out;
}

TEST(RunMerge, OneRowGivesItsRunsAndTheGapsBetween) {
  const std::vector<ValueRun> row{{2, 4, 7}, {6, 9, 3}};
  const std::vector<Interval<1>> want{
      {0, 2, {0}}, {2, 4, {7}}, {4, 6, {0}}, {6, 9, {3}}, {9, 12, {0}}};
  EXPECT_EQ(value_intervals<1>(12, 0, {row}), want);
}

TEST(RunMerge, AdjacentRunsOfDifferentValuesChangeWithoutAGap) {
  const std::vector<ValueRun> row{{1, 3, 1}, {3, 5, 2}, {5, 6, 1}};
  const std::vector<Interval<1>> want{
      {0, 1, {0}}, {1, 3, {1}}, {3, 5, {2}}, {5, 6, {1}}, {6, 8, {0}}};
  EXPECT_EQ(value_intervals<1>(8, 0, {row}), want);
  // As bits, the adjacent runs are one stretch inside, still cut where the runs meet.
  const std::vector<Interval<1>> bits{
      {0, 1, {0}}, {1, 3, {1}}, {3, 5, {1}}, {5, 6, {1}}, {6, 8, {0}}};
  EXPECT_EQ(bit_intervals<1>(8, 0, {row}), bits);
}

TEST(RunMerge, EmptyRowsAreBackgroundThroughout) {
  const std::vector<ValueRun> none;
  EXPECT_EQ(value_intervals<1>(5, 0, {none}), (std::vector<Interval<1>>{{0, 5, {0}}}));
  EXPECT_EQ(bit_intervals<2>(5, 0, {none, none}), (std::vector<Interval<2>>{{0, 5, {0, 0}}}));
  const std::vector<ValueRun> row{{1, 2, 4}};
  const std::vector<Interval<3>> want{{0, 1, {0, 0, 0}}, {1, 2, {0, 4, 0}}, {2, 5, {0, 0, 0}}};
  EXPECT_EQ(value_intervals<3>(5, 0, {none, row, none}), want);
}

TEST(RunMerge, IntervalsEndWhereverAnyRowChanges) {
  const std::vector<ValueRun> a{{1, 5, 1}, {7, 8, 2}};
  const std::vector<ValueRun> b{{3, 4, 3}, {4, 7, 1}};
  const std::vector<Interval<2>> want{{0, 1, {0, 0}}, {1, 3, {1, 0}}, {3, 4, {1, 3}},
                                      {4, 5, {1, 1}}, {5, 7, {0, 1}}, {7, 8, {2, 0}},
                                      {8, 10, {0, 0}}};
  EXPECT_EQ(value_intervals<2>(10, 0, {a, b}), want);
  const std::vector<Interval<2>> bits{{0, 1, {0, 0}}, {1, 3, {1, 0}}, {3, 4, {1, 1}},
                                      {4, 5, {1, 1}}, {5, 7, {0, 1}}, {7, 8, {1, 0}},
                                      {8, 10, {0, 0}}};
  EXPECT_EQ(bit_intervals<2>(10, 0, {a, b}), bits);
}

TEST(RunMerge, RunsAtTheEndsOfTheDomainAndAnOffset) {
  // Runs in global x 10..; local x = global x - 10. The first run starts at local 0, the last
  // reaches the end of the domain: no empty interval before or after.
  const std::vector<ValueRun> a{{10, 12, 5}, {13, 16, 6}};
  const std::vector<ValueRun> b{{10, 16, 9}};
  const std::vector<Interval<2>> want{{0, 2, {5, 9}}, {2, 3, {0, 9}}, {3, 6, {6, 9}}};
  EXPECT_EQ(value_intervals<2>(6, 10, {a, b}), want);
}

TEST(RunMerge, FourRowsCoverTheDomainInOrder) {
  const std::vector<ValueRun> r0{{1, 4, 1}}, r1{{2, 3, 2}, {3, 6, 1}}, r2, r3{{0, 1, 3}, {5, 6, 3}};
  const auto got = value_intervals<4>(7, 0, {r0, r1, r2, r3});
  const std::vector<Interval<4>> want{
      {0, 1, {0, 0, 0, 3}}, {1, 2, {1, 0, 0, 0}}, {2, 3, {1, 2, 0, 0}}, {3, 4, {1, 1, 0, 0}},
      {4, 5, {0, 1, 0, 0}}, {5, 6, {0, 1, 0, 3}}, {6, 7, {0, 0, 0, 0}}};
  EXPECT_EQ(got, want);
}

}  // namespace
}  // namespace segmesh
