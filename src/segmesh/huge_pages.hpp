// Large buffers backed by transparent huge pages, where the system grants them on request
// (/sys/kernel/mm/transparent_hugepage/enabled = madvise, Debian's default): the first write to a
// fresh 2 MB region then costs one page fault instead of 512. Meshes, adjacency rows and smoothing
// state are written once into fresh memory; on make_big.py's volume the 4 kB page faults were a
// third of Marching Cubes' time. A hint only: where it is refused nothing changes.
#pragma once

#include <cstddef>
#include <vector>

namespace segmesh {

// Advises huge pages for the 2 MB-aligned part of [p, p + bytes); does nothing below 4 MB.
void advise_huge_pages(void* p, size_t bytes);

// v.resize(n) with the new storage advised first (for a vector about to be filled).
template <class T, class A>
void resize_huge(std::vector<T, A>& v, size_t n) {
  if (n > v.capacity()) {
    std::vector<T, A> fresh;
    fresh.reserve(n);  // allocated, not yet touched
    advise_huge_pages(fresh.data(), n * sizeof(T));
    fresh.assign(v.begin(), v.end());
    v.swap(fresh);
  }
  v.resize(n);
}

}  // namespace segmesh
