// Per-vertex sums over triangles (triangle_scatter.hpp): the chunks cover every triangle once,
// chunks of one parity touch disjoint vertex ids, scattered ids end up in one chunk, and a scatter
// of floating-point terms gives the same bits at any thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <random>
#include <vector>

#include "segmesh/detail/triangle_scatter.hpp"
#include "segmesh/marching_cubes.hpp"
#include "support/test_fields.hpp"

namespace segmesh {
namespace {

// Marching Cubes of a random 0/1 field: about 10^5 triangles, numbered plane by plane.
TriMesh random_blobs() {
  return marching_cubes(test::random_coins({48, 40, 40}, 5), {});
}

void expect_valid(const TriangleChunks& chunks, const std::vector<uint32_t>& idx) {
  ASSERT_GE(chunks.count(), 1u);
  EXPECT_EQ(chunks.first.front(), 0u);
  EXPECT_EQ(chunks.first.back(), idx.size() / 3);
  for (size_t c = 0; c < chunks.count(); ++c) ASSERT_LT(chunks.first[c], chunks.first[c + 1]);
  for (size_t c = 0; c < chunks.count(); ++c) {
    const auto [lo, hi] = vertex_range(idx, chunks.first[c], chunks.first[c + 1]);
    for (size_t d = c + 2; d < chunks.count(); d += 2) {
      const auto [lo2, hi2] = vertex_range(idx, chunks.first[d], chunks.first[d + 1]);
      EXPECT_TRUE(hi < lo2 || hi2 < lo) << "chunks " << c << " and " << d << " share vertex ids";
    }
  }
}

TEST(TriangleScatter, VertexRangeIsTheExactMinimumAndMaximum) {
  const std::vector<uint32_t> idx = {7, 3, 9, 0x80000001u, 2, 5, 4, 4, 0xffffffffu};
  EXPECT_EQ(vertex_range(idx, 0, 1), std::make_pair(3u, 9u));
  EXPECT_EQ(vertex_range(idx, 0, 2), std::make_pair(2u, 0x80000001u));
  EXPECT_EQ(vertex_range(idx, 2, 3), std::make_pair(4u, 0xffffffffu));
}

TEST(TriangleScatter, OrderedMeshesKeepManyDisjointChunksScatteredIdsMergeToOne) {
  const TriMesh mesh = random_blobs();
  const size_t nt = mesh.triangle_count();
  ASSERT_GT(nt, 60000u);
  const TriangleChunks ordered = triangle_chunks(mesh.indices, 2048);
  expect_valid(ordered, mesh.indices);
  EXPECT_GE(ordered.count(), 8u);  // Marching Cubes numbers vertices and triangles plane by plane

  // The same mesh with its vertex ids shuffled: every chunk spans nearly all ids.
  std::vector<uint32_t> perm(mesh.positions.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(3));
  std::vector<uint32_t> shuffled = mesh.indices;
  for (uint32_t& v : shuffled) v = perm[v];
  const TriangleChunks merged = triangle_chunks(shuffled, 2048);
  expect_valid(merged, shuffled);
  EXPECT_EQ(merged.count(), 1u);

  // Small meshes: one chunk.
  EXPECT_EQ(triangle_chunks(mesh.indices).count() >= 3, nt >= 3 * (size_t{1} << 14));
  EXPECT_EQ(triangle_chunks({0, 1, 2, 2, 1, 3}).count(), 1u);
  EXPECT_EQ(triangle_chunks({}).count(), 1u);
}

TEST(TriangleScatter, SumsAreCompleteAndTheSameBitsAtAnyThreadCount) {
  const TriMesh mesh = random_blobs();
  const TriangleChunks chunks = triangle_chunks(mesh.indices, 2048);
  ASSERT_GE(chunks.count(), 8u);
  const size_t nv = mesh.positions.size();
  // Each corner gets its triangle count (exact) and a float sum whose rounding depends on the
  // order of its terms.
  auto scatter = [&](int threads) {
    std::vector<int> count(nv, 0);
    std::vector<float> sum(nv, 0.0f);
    tbb::task_arena(threads).execute([&] {
      scatter_triangles(chunks, [&](size_t t0, size_t t1) {
        for (size_t t = t0; t < t1; ++t) {
          const float term = 1.0f / float(t + 3);
          for (int k = 0; k < 3; ++k) {
            const uint32_t v = mesh.indices[3 * t + k];
            ++count[v];
            sum[v] += term;
          }
        }
      });
    });
    return std::make_pair(count, sum);
  };
  const auto [count1, sum1] = scatter(1);
  std::vector<int> expected(nv, 0);
  for (uint32_t v : mesh.indices) ++expected[v];
  EXPECT_EQ(count1, expected);
  for (int threads : {2, 4}) {
    const auto [count, sum] = scatter(threads);
    EXPECT_EQ(count, expected) << threads;
    EXPECT_EQ(0, std::memcmp(sum.data(), sum1.data(), nv * sizeof(float))) << threads;
  }
}

// A vertex pass fused into the scatter (scatter_then_finish) visits every vertex once, after all
// its terms, and sees the bits of the plain scatter, ordered ids (many chunks) and shuffled (one).
TEST(TriangleScatter, FusedPassSeesEveryVertexOnceWithItsCompleteSums) {
  const TriMesh mesh = random_blobs();
  const size_t nv = mesh.positions.size() + 5;  // a few ids no triangle uses: the rest
  std::vector<uint32_t> scattered = mesh.indices;
  std::vector<uint32_t> perm(mesh.positions.size());
  std::iota(perm.begin(), perm.end(), 0u);
  std::shuffle(perm.begin(), perm.end(), std::mt19937(5));
  for (uint32_t& v : scattered) v = perm[v];
  const std::vector<uint32_t>& ordered = mesh.indices;
  for (const std::vector<uint32_t>* idx :
       {&ordered, static_cast<const std::vector<uint32_t>*>(&scattered)}) {
    const TriangleChunks chunks = triangle_chunks(*idx, 2048);
    const FinishPlan plan = finish_plan(chunks, nv);
    // Ordered ids: the chunks finish their vertices; one chunk: all are the rest.
    EXPECT_EQ(plan.first.back() > 0, idx == &ordered);
    auto add = [&](std::vector<float>& sum) {
      return [&](size_t t0, size_t t1) {
        for (size_t t = t0; t < t1; ++t)
          for (int k = 0; k < 3; ++k) sum[(*idx)[3 * t + k]] += 1.0f / float(t + 3);
      };
    };
    std::vector<float> plain(nv, 0.0f);
    scatter_triangles(chunks, add(plain));
    for (int threads : {1, 2, 4}) {
      std::vector<float> sum(nv, 0.0f), seen(nv, -1.0f);
      std::vector<int> visits(nv, 0);
      tbb::task_arena(threads).execute([&] {
        scatter_then_finish(chunks, plan, add(sum), [&](size_t v0, size_t v1) {
          for (size_t v = v0; v < v1; ++v) {
            ++visits[v];
            seen[v] = sum[v];
          }
        });
      });
      EXPECT_EQ(visits, std::vector<int>(nv, 1)) << threads;
      EXPECT_EQ(0, std::memcmp(seen.data(), plain.data(), nv * sizeof(float))) << threads;
    }
  }
}

TEST(TriangleScatter, InterleavedWalkVisitsEveryTriangleOnceInStreamsAQuarterBlockApart) {
  constexpr size_t kBlock = size_t{1} << 16;
  for (const auto& [first, last] : std::vector<std::pair<size_t, size_t>>{
           {0, 0}, {3, 4}, {10, 17}, {5, 5 + kBlock}, {7, 7 + 2 * kBlock + 13}}) {
    std::vector<int> seen(last + 1, 0);
    std::vector<size_t> order;
    for_each_interleaved(first, last, [&](size_t t) {
      ++seen[t];
      order.push_back(t);
    });
    for (size_t t = 0; t <= last; ++t)
      ASSERT_EQ(seen[t], t >= first && t < last ? 1 : 0) << first << " " << last << " " << t;
    if (last - first >= kBlock) {  // a full block: four streams a quarter block apart
      EXPECT_EQ(order[1], first + kBlock / 4);
      EXPECT_EQ(order[4], first + 1);
    }
  }
}

}  // namespace
}  // namespace segmesh
