// The machine's limit for the smoothing sweeps' vertex update (docs/PERFORMANCE.md, "The
// smoothing sweeps against the machine's limit"): a loop of its shape, 3 reads and 2 writes of
// float4 per element, over THREADS equal slices of N elements, best of 20, with and without
// software prefetch 64 elements ahead.
//   segmesh_stream_f4 THREADS N      (N = 2700000: big_seg's vertices, 43 MB per array)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

typedef float F4 __attribute__((vector_size(16)));

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: segmesh_stream_f4 THREADS N\n");
    return 2;
  }
  const int threads = std::max(1, std::atoi(argv[1]));
  const size_t n = std::strtoull(argv[2], nullptr, 10);
  std::vector<F4> a(n + 64, F4{1, 1, 1, 1}), b(n + 64, F4{}), c(n + 64, F4{2, 2, 2, 2});
  for (const bool prefetch : {false, true}) {
    double best = 1e30;
    for (int rep = 0; rep < 20; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      std::vector<std::thread> pool;
      for (int t = 0; t < threads; ++t) {
        pool.emplace_back([&, t] {
          for (size_t i = n * t / threads, e = n * (t + 1) / threads; i < e; ++i) {
            if (prefetch) {
              __builtin_prefetch(&a[i + 64]);
              __builtin_prefetch(&b[i + 64]);
              __builtin_prefetch(&c[i + 64]);
            }
            const F4 y = 0.5f * a[i];
            a[i] = y;
            b[i] = 2.0f * y + (0.25f * c[i] - b[i]);
          }
        });
      }
      for (std::thread& th : pool) th.join();
      best = std::min(best,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    }
    std::printf(
        "threads %d, %zu elements (%.0f MB per array), prefetch %s: %.1f GB/s, %.2f ns per "
        "element\n",
        threads, n, 16e-6 * double(n), prefetch ? "on " : "off", 80.0 * double(n) / best * 1e-9,
        best / double(n) * 1e9);
  }
}
