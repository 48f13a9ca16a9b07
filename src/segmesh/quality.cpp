#include "segmesh/quality.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace segmesh {

namespace {

// Triangles per block of the parallel reductions. The block boundaries, not the threads, decide
// the order of the floating-point sums, which is what makes the mean thread-count independent.
constexpr size_t kBlock = 4096;

double triangle_rho(const TriMesh& mesh, size_t t) {
  const uint32_t* v = &mesh.indices[3 * t];
  return radii_ratio(to_double(mesh.positions[v[0]]), to_double(mesh.positions[v[1]]),
                     to_double(mesh.positions[v[2]]));
}

int histogram_bin(double rho) {
  return std::min(static_cast<int>(rho * 10), 9);
}

}  // namespace

double radii_ratio(Vec3d p, Vec3d q, Vec3d r) {
  return radii_ratio_of_sides(norm(q - r), norm(r - p), norm(p - q));
}

double radii_ratio_of_sides(double a, double b, double c) {
  if (a < b) std::swap(a, b);
  if (b < c) std::swap(b, c);
  if (a < b) std::swap(a, b);
  if (!(c > 0)) return 0;
  // Kahan's parenthesisation: every difference is of exact or nearly exact quantities.
  const double f1 = std::max(c - (a - b), 0.0);
  const double f2 = c + (a - b);
  const double f3 = a + (b - c);
  const double rho = f1 * f2 * f3 / (a * b * c);
  return rho > 0 ? std::min(rho, 1.0) : 0.0;  // NaN (non-finite corners) counts as degenerate
}

double percentile(std::vector<double>& values, double q) {
  const size_t n = values.size();
  if (n == 0) return 0;
  const double index = std::clamp(q, 0.0, 1.0) * double(n - 1);
  const size_t lo = std::min(static_cast<size_t>(index), n - 1);
  const double t = index - double(lo);
  std::nth_element(values.begin(), values.begin() + lo, values.end());
  const double a = values[lo];
  if (lo + 1 >= n || t == 0) return a;
  const double b = *std::min_element(values.begin() + lo + 1, values.end());
  // numpy's _lerp: anchored at the nearer end so that t = 1 gives b exactly.
  return t < 0.5 ? a + (b - a) * t : b - (b - a) * (1 - t);
}

QualityStats triangle_quality(const TriMesh& mesh) {
  QualityStats s;
  const size_t nt = mesh.triangle_count();
  s.triangles = static_cast<int64_t>(nt);
  if (nt == 0) return s;

  std::vector<double> rho(nt);
  const size_t blocks = (nt + kBlock - 1) / kBlock;
  struct BlockStats {
    double sum = 0, min = 1;
    std::array<int64_t, 10> histogram{};
  };
  std::vector<BlockStats> per_block(blocks);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, blocks),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t b = r.begin(); b != r.end(); ++b) {
                        BlockStats& bs = per_block[b];
                        const size_t end = std::min(nt, (b + 1) * kBlock);
                        for (size_t t = b * kBlock; t < end; ++t) {
                          const double q = triangle_rho(mesh, t);
                          rho[t] = q;
                          bs.sum += q;
                          bs.min = std::min(bs.min, q);
                          ++bs.histogram[histogram_bin(q)];
                        }
                      }
                    });

  double sum = 0;
  s.min = 1;
  for (const BlockStats& bs : per_block) {
    sum += bs.sum;
    s.min = std::min(s.min, bs.min);
    for (int k = 0; k < 10; ++k) s.histogram[k] += bs.histogram[k];
  }
  s.mean = sum / double(nt);
  s.p01 = percentile(rho, 0.01);
  return s;
}

std::vector<float> vertex_quality(const TriMesh& mesh) {
  std::vector<float> out(mesh.positions.size(), 1.0f);
  const size_t nt = mesh.triangle_count();
  // A minimum does not depend on the order in which triangles arrive, so concurrent
  // compare-and-swap updates give the same values for any thread count.
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, nt, kBlock), [&](const tbb::blocked_range<size_t>& r) {
        for (size_t t = r.begin(); t != r.end(); ++t) {
          const float q = static_cast<float>(triangle_rho(mesh, t));
          for (int k = 0; k < 3; ++k) {
            std::atomic_ref<float> slot(out[mesh.indices[3 * t + k]]);
            float seen = slot.load(std::memory_order_relaxed);
            while (q < seen && !slot.compare_exchange_weak(seen, q, std::memory_order_relaxed)) {
            }
          }
        }
      });
  return out;
}

std::vector<Rgba8> quality_colors(const std::vector<float>& rho) {
  std::vector<Rgba8> out(rho.size());
  for (size_t i = 0; i < rho.size(); ++i) {
    const float q = std::isnan(rho[i]) ? 0.0f : std::clamp(rho[i], 0.0f, 1.0f);
    const auto green = static_cast<uint8_t>(std::lround(255.0f * q));
    out[i] = {0, green, static_cast<uint8_t>(255 - green), 255};
  }
  return out;
}

}  // namespace segmesh
