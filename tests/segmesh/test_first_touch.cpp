// resize_zeroed: the same result as std::vector::resize (old elements kept, new ones zero) for
// any growth, shrink and thread count, including sizes around the parallel threshold and the
// page size. first_touch: every page of its range resident afterwards, nothing outside written.
#include "segmesh/first_touch.hpp"

#include <gtest/gtest.h>
#include <sys/mman.h>
#include <tbb/task_arena.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "segmesh/vec3.hpp"

namespace segmesh {
namespace {

template <class T>
void expect_like_resize(std::vector<T> v, size_t n, int threads) {
  std::vector<T> expected = v;
  expected.resize(n);
  tbb::task_arena(threads).execute([&] { resize_zeroed(v, n); });
  ASSERT_EQ(v.size(), n);
  // (memcmp only when there is something to compare: an empty vector's data() may be null.)
  if (n > 0) {
    EXPECT_EQ(0, std::memcmp(v.data(), expected.data(), n * sizeof(T)))
        << "n = " << n << ", threads = " << threads;
  }
}

TEST(FirstTouch, ResizeZeroedMatchesResize) {
  const size_t big = kParallelFirstTouchBytes / sizeof(uint32_t);
  for (int threads : {1, 2, 4}) {
    // Grown from empty, below, at and above the threshold, and by a number of bytes that is not a
    // whole number of pages.
    for (size_t n : {size_t{0}, size_t{1}, big - 1, big, big + 1, 3 * big + 777})
      expect_like_resize(std::vector<uint32_t>{}, n, threads);
    // Grown from a filled vector whose end is inside a page: the old values stay.
    std::vector<uint32_t> filled(1025);
    for (size_t i = 0; i < filled.size(); ++i) filled[i] = uint32_t(i * 2654435761u);
    expect_like_resize(filled, 2 * big + 3, threads);
    // Shrunk, and kept.
    expect_like_resize(filled, 10, threads);
    expect_like_resize(filled, filled.size(), threads);
  }
  // An element type of 12 bytes (positions): pages split its elements.
  std::vector<Vec3f> positions(5, Vec3f{1, 2, 3});
  tbb::task_arena(2).execute([&] { resize_zeroed(positions, kParallelFirstTouchBytes / 12 + 5); });
  EXPECT_EQ(positions[4].z, 3.0f);
  for (size_t i = 5; i < positions.size(); ++i) {
    ASSERT_EQ(positions[i].x, 0.0f);
    ASSERT_EQ(positions[i].y, 0.0f);
    ASSERT_EQ(positions[i].z, 0.0f);
  }
}

TEST(FirstTouch, MakesEveryPageOfItsRangeResidentAndWritesNothingOutside) {
  constexpr size_t kPage = 4096, kPages = 1024;  // 4 MB of fresh memory per round
  for (int threads : {1, 2}) {
    void* map = mmap(nullptr, kPages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS,
                     -1, 0);
    ASSERT_NE(map, MAP_FAILED);
    auto* bytes = static_cast<unsigned char*>(map);
    // Marks just outside the range, on the partial pages at both of its ends.
    const size_t first = 3 * kPage + 100, last = (kPages - 2) * kPage + 7;  // [first, last)
    bytes[first - 1] = 0xa5;
    bytes[last] = 0x5a;
    tbb::task_arena(threads).execute([&] { first_touch(bytes + first, last - first); });
    std::vector<unsigned char> resident(kPages);
    ASSERT_EQ(0, mincore(map, kPages * kPage, resident.data()));
    for (size_t p = first / kPage; p <= (last - 1) / kPage; ++p)
      ASSERT_TRUE(resident[p] & 1) << "page " << p << ", threads = " << threads;
    // The pages wholly outside were never touched, and the marks are as written.
    EXPECT_FALSE(resident[0] & 1);
    EXPECT_FALSE(resident[kPages - 1] & 1);
    EXPECT_EQ(bytes[first - 1], 0xa5);
    EXPECT_EQ(bytes[last], 0x5a);
    munmap(map, kPages * kPage);
  }
}

}  // namespace
}  // namespace segmesh
