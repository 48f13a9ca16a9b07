// Growing a large array with its fresh memory made resident first, by every thread.
//
// The first write to a page the process has never used costs a page fault in which the kernel
// finds and zeroes a page: on the virtual machines segmesh is measured on, more than a pass of
// arithmetic over the same data (docs/PERFORMANCE.md has the measurements). std::vector::resize zero-fills the new
// elements from the calling thread, so every fault of an output array is taken in that one
// thread, while the parallel loop that fills the array afterwards waits. Faults taken by several
// threads at once proceed side by side, and a page range the kernel is asked to populate in one
// call costs less than the same pages faulted one write at a time. first_touch therefore
// asks the kernel for each task's pages (MADV_POPULATE_WRITE), from a parallel loop, before the
// array's first pass; resize_zeroed does that and only then resizes, so the zero fill runs over
// resident pages at memory speed. Same result as resize(n): the new elements
// are zero. On kernels before 5.14, which refuse the request, one byte per page is written.
//
// Below kParallelFirstTouchBytes nothing is done beforehand (resize_zeroed: a plain resize), and
// with one thread the pages are populated by one call from the calling thread. The bound is 1 MB
// (256 pages, four tasks of 64): small enough that the outputs of mid-sized parts (a pelvis
// fragment's few MB) are populated in parallel, large enough that the many small parts extracted
// side by side do not pay for tasks.
#pragma once

#include <sys/mman.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
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

// Makes the pages of [data, data + bytes) resident, from every thread (first_touch_threads), when
// they span at least kParallelFirstTouchBytes (smaller ranges are left to their first pass).
// Each task asks the kernel to fault its page range in at once (Linux's MADV_POPULATE_WRITE, 5.14
// and later), which costs less than faulting the same pages one write at a time; where the
// kernel refuses,
// it writes one byte per page. For raw storage that holds no object yet; it writes nothing but
// zeros, so zeroed storage (calloc's) stays zero.
inline void first_touch(void* data, size_t bytes) {
  if (bytes < kParallelFirstTouchBytes) return;
  constexpr uintptr_t kPage = 4096;
  const uintptr_t begin = reinterpret_cast<uintptr_t>(data), end = begin + bytes;
  auto touch = [](uintptr_t lo, uintptr_t hi) {  // lo < hi
#if defined(__linux__)
    constexpr int kPopulateWrite = 23;  // MADV_POPULATE_WRITE, not in every libc's headers
    const uintptr_t lo_page = (lo + kPage - 1) & ~(kPage - 1), hi_page = hi & ~(kPage - 1);
    if (hi_page > lo_page &&
        madvise(reinterpret_cast<void*>(lo_page), hi_page - lo_page, kPopulateWrite) == 0) {
      // The partial pages at both ends, by hand.
      if (lo < lo_page) *reinterpret_cast<volatile char*>(lo) = 0;
      if (hi > hi_page) *reinterpret_cast<volatile char*>(hi_page) = 0;
      return;
    }
#endif
    for (uintptr_t p = lo; p < hi; p = (p & ~(kPage - 1)) + kPage)
      *reinterpret_cast<volatile char*>(p) = 0;
  };
  if (first_touch_threads() <= 1) {
    touch(begin, end);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<uintptr_t>(begin / kPage, (end - 1) / kPage + 1, 64),
                    [&](const tbb::blocked_range<uintptr_t>& pages) {
                      touch(std::max(begin, pages.begin() * kPage),
                            std::min(end, pages.end() * kPage));
                    });
}

// resize(n), with the new elements' pages made resident by first_touch before they are zeroed,
// when they span at least kParallelFirstTouchBytes.
template <class T>
void resize_zeroed(std::vector<T>& v, size_t n) {
  static_assert(std::is_trivially_copyable_v<T>, "raw first touch of the new capacity");
  const size_t old = v.size();
  if (n > old && (n - old) * sizeof(T) >= kParallelFirstTouchBytes) {
    v.reserve(n);
    // Raw storage beyond the elements: no object is read or written (resize creates them next).
    first_touch(reinterpret_cast<char*>(v.data()) + old * sizeof(T), (n - old) * sizeof(T));
  }
  v.resize(n);
}

}  // namespace segmesh
