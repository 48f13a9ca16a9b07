// Growing a large array with its fresh memory touched by every thread.
//
// The first write to a page the process has never used costs a page fault in which the kernel
// finds and zeroes a page: 0.65-0.85 ms per MB on the 2-core virtual machines segmesh is measured
// on, more than a pass of arithmetic over the same data. std::vector::resize zero-fills the new
// elements from the calling thread, so every fault of an output array is taken in that one
// thread, while the parallel loop that fills the array afterwards waits. Faults taken by several
// threads at once proceed side by side (125 MB first touched in 92-104 ms from one thread, 54-59 ms
// from two, docs/PERFORMANCE.md). resize_zeroed therefore first writes one byte per new page from
// a parallel loop and only then resizes; the zero fill then runs over resident pages at memory
// speed (7 ms for 125 MB). Same result as resize(n): the new elements are zero.
//
// Below kParallelFirstTouchBytes of growth, or with one thread (where the extra pass would only
// cost), it is a plain resize. The bound is 1 MB (256 pages, four tasks of 64): the pelvis's two
// parts have 2.6 and 1.3 MB of output, and their Marching Cubes at two threads took 2.9 ms with a
// 4 MB bound and 2.6 ms with this one (single runs, docs/PERFORMANCE.md); the phantom's ten parts,
// extracted side by side, were no slower.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <type_traits>
#include <vector>

namespace segmesh {

inline constexpr size_t kParallelFirstTouchBytes = size_t{1} << 20;

// The threads a parallel loop here can use: the arena's, capped by a global_control (which the
// command line's --threads sets and the arena's size does not show).
inline int first_touch_threads() {
  const size_t allowed =
      tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism);
  return std::min(tbb::this_task_arena::max_concurrency(),
                  static_cast<int>(std::min<size_t>(allowed, 1024)));
}

template <class T>
void resize_zeroed(std::vector<T>& v, size_t n) {
  static_assert(std::is_trivially_copyable_v<T>, "raw first touch of the new capacity");
  const size_t old = v.size();
  if (n > old && (n - old) * sizeof(T) >= kParallelFirstTouchBytes && first_touch_threads() > 1) {
    v.reserve(n);
    // One byte per page of the storage reserve() allocated, beyond the elements: raw memory, no
    // object is written (resize creates them next).
    volatile char* storage = reinterpret_cast<char*>(v.data());
    const size_t begin = old * sizeof(T), end = n * sizeof(T);
    constexpr size_t kPage = 4096;
    tbb::parallel_for(tbb::blocked_range<size_t>(begin / kPage, (end - 1) / kPage + 1, 64),
                      [&](const tbb::blocked_range<size_t>& pages) {
                        for (size_t p = pages.begin(); p != pages.end(); ++p)
                          storage[std::max(begin, p * kPage)] = 0;
                      });
  }
  v.resize(n);
}

}  // namespace segmesh
