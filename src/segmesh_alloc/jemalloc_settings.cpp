// jemalloc's settings for segmesh's programs: jemalloc reads this symbol when it starts (before
// main), so they hold for every allocation, the libraries' (ITK, TBB, Mesa) included. An
// environment's MALLOC_CONF is read after it and can override them.
//
// thp:always  jemalloc marks its memory for transparent huge pages (MADV_HUGEPAGE). Where the
//             kernel's setting is "madvise" (Debian's default), nothing else gets them, and every
//             4 KB page a command writes first costs a page fault: on the built-in phantom the
//             default command took 40 000 of them, which were a third of its time on the
//             virtual machines segmesh is measured on. With 2 MB pages it takes about 3 000.
//             Where the kernel's setting is "never" this does nothing.
// metadata_thp:auto  the same for jemalloc's own bookkeeping once it grows.
// Freed memory is kept for reuse for jemalloc's default 10 s (dirty_decay_ms), which saves the
// faults of memory freed by one step and allocated by the next.
// Measured in docs/PERFORMANCE.md ("The programs' allocator").
extern "C" {
// NOLINTNEXTLINE(cppcoreguidelines-avoid-non-const-global-variables): jemalloc's interface
const char* malloc_conf = "thp:always,metadata_thp:auto";
}
