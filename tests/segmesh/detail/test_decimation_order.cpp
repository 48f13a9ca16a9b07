// The cost buckets of decimation (detail/decimation_order.hpp): cheapest octave first; within an
// octave, vertex order when its order does not matter and buckets 1/16 of an octave wide when it
// does (a budget may stop there); candidates no longer current dropped; candidates pushed into a
// bucket already reached first; pops up to a bucket.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "segmesh/detail/decimation_order.hpp"

namespace segmesh {
namespace {

Candidate at(double cost, uint32_t keep, uint32_t remove = 0) {
  Candidate c;
  c.cost = cost;
  c.keep = keep;
  c.remove = remove;
  return c;
}

// Pops everything, returning the keep vertices in the order taken.
template <class Current, class Exact>
std::vector<uint32_t> drain(CostBuckets& q, Current&& current, Exact&& exact) {
  std::vector<uint32_t> order;
  Candidate c;
  while (q.pop(c, current, exact)) order.push_back(c.keep);
  return order;
}

// Three costs of the octave [0.125, 0.25) in three of its fine buckets and one of the octave
// below, in no order.
void push_spread(CostBuckets& q) {
  q.push(at(0.19, 5));
  q.push(at(0.11, 9));
  q.push(at(0.15, 2));
  q.push(at(0.13, 7));
}

const auto kAll = [](const Candidate&) { return true; };
const auto kNever = [](double, size_t) { return false; };
const auto kAlways = [](double, size_t) { return true; };

TEST(DecimationOrder, AnOctaveGoesInVertexOrderAfterTheCheaperOctaves) {
  CostBuckets q;
  push_spread(q);
  q.push(at(0.05, 30));
  q.push(at(0.3, 1));
  EXPECT_EQ(drain(q, kAll, kNever), (std::vector<uint32_t>{30, 9, 2, 5, 7, 1}));
}

TEST(DecimationOrder, AnOctaveWhoseOrderMattersGoesCheapestFirst) {
  CostBuckets q;
  push_spread(q);
  // Each fine bucket 4.4 % wide: 0.11, 0.13, 0.15 and 0.19 fall in four of them.
  EXPECT_EQ(drain(q, kAll, kAlways), (std::vector<uint32_t>{9, 7, 2, 5}));
}

// The block phase's rounds: pops stop after a given bucket; next_bucket names the first that
// holds candidates.
TEST(DecimationOrder, PopsStopAfterTheBucketAskedFor) {
  CostBuckets q;
  EXPECT_EQ(q.next_bucket(), CostBuckets::bucket_count());
  push_spread(q);
  const size_t b13 = CostBuckets::bucket(0.13);
  EXPECT_EQ(q.next_bucket(), CostBuckets::bucket(0.11));
  std::vector<uint32_t> order;
  Candidate c;
  auto none = [](const Candidate&) {};
  while (q.pop(c, kAll, kAlways, none, b13)) order.push_back(c.keep);
  EXPECT_EQ(order, (std::vector<uint32_t>{9, 7}));
  EXPECT_EQ(q.next_bucket(), CostBuckets::bucket(0.15));
  EXPECT_EQ(drain(q, kAll, kAlways), (std::vector<uint32_t>{2, 5}));
}

TEST(DecimationOrder, ExactIsAskedWithTheOctavesBoundAndCount) {
  CostBuckets q;
  q.push(at(0.11, 1));
  q.push(at(0.19, 2));
  q.push(at(0.3, 3));
  std::vector<std::pair<double, size_t>> asked;
  const auto record = [&](double upper, size_t count) {
    asked.push_back({upper, count});
    return false;
  };
  drain(q, kAll, record);
  // Three octaves: [1/16, 1/8), [1/8, 1/4) and [1/4, 1/2), one candidate each.
  ASSERT_EQ(asked.size(), 3u);
  EXPECT_DOUBLE_EQ(asked[0].first, 0.125);
  EXPECT_DOUBLE_EQ(asked[1].first, 0.25);
  EXPECT_DOUBLE_EQ(asked[2].first, 0.5);
  for (const auto& [upper, count] : asked) EXPECT_EQ(count, 1u) << upper;
}

TEST(DecimationOrder, CandidatesNoLongerCurrentAreDroppedAndPushesComeFirst) {
  CostBuckets q;
  for (uint32_t v = 0; v < 6; ++v) q.push(at(0.1 + 0.001 * v, v));
  const auto even = [](const Candidate& c) { return c.keep % 2 == 0; };
  Candidate c;
  ASSERT_TRUE(q.pop(c, even, kNever));
  EXPECT_EQ(c.keep, 0u);
  // Pushed into the bucket being taken: next, before the rest of the sweep.
  q.push(at(0.1, 11));
  q.push(at(0.1, 13));
  std::vector<uint32_t> rest = drain(q, kAll, kNever);
  EXPECT_EQ(rest, (std::vector<uint32_t>{13, 11, 2, 4}));
}

TEST(DecimationOrder, ZeroAndHugeCostsHaveBuckets) {
  CostBuckets q;
  q.push(at(1e30, 3));
  q.push(at(0.0, 2));
  q.push(at(1e-50, 1));
  // 0 and 1e-50 share the first bucket (vertex order), 1e30 the last.
  EXPECT_EQ(drain(q, kAll, kNever), (std::vector<uint32_t>{1, 2, 3}));
}

}  // namespace
}  // namespace segmesh
