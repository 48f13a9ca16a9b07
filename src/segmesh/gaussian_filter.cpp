#include "segmesh/gaussian_filter.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <vector>

#include "segmesh/component_field.hpp"

namespace segmesh {

namespace {

// ceil(3 sigma), robust against sigma_mm / spacing landing a hair above an integer third.
int64_t truncation_radius(double sigma_voxels) {
  if (!(sigma_voxels > 0)) return 0;
  assert(std::isfinite(sigma_voxels));
  return static_cast<int64_t>(std::ceil(3 * sigma_voxels - 1e-9));
}

// Half of a symmetric kernel: w[t] is the weight of the taps at -t and +t; radius 0 is the identity.
struct Kernel {
  int64_t radius = 0;
  std::vector<float> w;
};

Kernel make_kernel(double sigma_voxels) {
  Kernel k;
  if (!(sigma_voxels >= kGaussianMinSigmaVoxels)) {
    k.w = {1.0f};
    return k;
  }
  k.radius = truncation_radius(sigma_voxels);
  std::vector<double> w(static_cast<size_t>(k.radius) + 1);
  double sum = 0;
  for (int64_t t = 0; t <= k.radius; ++t) {
    w[t] = std::exp(-0.5 * double(t * t) / (sigma_voxels * sigma_voxels));
    sum += (t == 0 ? 1 : 2) * w[t];
  }
  for (double x : w) k.w.push_back(static_cast<float>(x / sum));
  return k;
}

// out[i] = w0 c[i] + sum_t w_t (lo_t[i] + hi_t[i]) for i < n, where lo_t / hi_t are the rows (or
// row offsets) t taps before / after. Every element goes through the same operations in the same
// order, whichever loop version (vector or scalar remainder) the compiler picks for it, which is
// what makes the output independent of how the work is split.
template <class RowAt>
void convolve(const Kernel& k, const float* center, RowAt&& row_at, int64_t n,
              float* __restrict out) {
  const float w0 = k.w[0];
  for (int64_t i = 0; i < n; ++i) out[i] = w0 * center[i];
  for (int64_t t = 1; t <= k.radius; ++t) {
    const float wt = k.w[t];
    const float* lo = row_at(-t);
    const float* hi = row_at(t);
    for (int64_t i = 0; i < n; ++i) out[i] += wt * (lo[i] + hi[i]);
  }
}

struct SliceScratch {
  std::vector<float> row;      // one padded row (x pass)
  std::vector<float> slice;    // the x-filtered slice (y pass input)
  std::vector<float> outside;  // a row of `outside` (y pass beyond the volume)
};

struct BlockScratch {
  std::vector<float> block;    // the block's rows along z, unfiltered
  std::vector<float> outside;  // a block row of `outside`
};

// Width of the z pass's blocks: whole rows when they fit, else a multiple of 16 floats such that a
// block of nz rows stays near 1 MB.
int64_t z_block_width(int64_t nx, int64_t nz) {
  const int64_t fit = std::max<int64_t>(16, (int64_t{1} << 18) / std::max<int64_t>(nz, 1) / 16 * 16);
  return std::min(nx, fit);
}

}  // namespace

std::array<int64_t, 3> gaussian_radius(const Grid& grid, double sigma_mm) {
  std::array<int64_t, 3> r{};
  for (int a = 0; a < 3; ++a) r[a] = make_kernel(sigma_mm / grid.spacing[a]).radius;
  return r;
}

std::array<int64_t, 3> gaussian_margin(const Grid& grid, double sigma_mm) {
  std::array<int64_t, 3> m{};
  for (int a = 0; a < 3; ++a) m[a] = truncation_radius(sigma_mm / grid.spacing[a]) + kFieldMargin;
  return m;
}

template <class T>
Volume<float> gaussian_filter(const Volume<T>& volume, double sigma_mm, float outside,
                              Progress& progress) {
  const Grid& g = volume.grid;
  assert(volume.voxels.size() == g.voxel_count());
  Volume<float> result;
  result.grid = g;
  result.voxels.resize(g.voxel_count());
  if (result.voxels.empty()) return result;

  const int64_t nx = g.dims[0], ny = g.dims[1], nz = g.dims[2];
  const size_t row_size = static_cast<size_t>(nx), slice_size = static_cast<size_t>(nx * ny);
  const Kernel kx = make_kernel(sigma_mm / g.spacing[0]);
  const Kernel ky = make_kernel(sigma_mm / g.spacing[1]);
  const Kernel kz = make_kernel(sigma_mm / g.spacing[2]);

  const int64_t block_width = z_block_width(nx, nz);
  const int64_t blocks_per_plane = (nx + block_width - 1) / block_width;
  const int64_t z_blocks = kz.radius > 0 ? ny * blocks_per_plane : 0;
  const double work_units = double(nz + z_blocks);
  std::atomic<int64_t> units_done{0};
  auto report = [&](int64_t units) {
    progress.update(double(units_done += units) / work_units);
  };

  // x and y passes, one z-slice at a time: volume slice -> (x) scratch slice -> (y) result slice.
  tbb::enumerable_thread_specific<SliceScratch> slice_scratch([&] {
    SliceScratch s;
    s.row.assign(row_size + 2 * static_cast<size_t>(kx.radius), outside);
    if (ky.radius > 0) {
      s.slice.resize(slice_size);
      s.outside.assign(row_size, outside);
    }
    return s;
  });
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, nz), [&](const tbb::blocked_range<int64_t>& r) {
    throw_if_cancelled(progress);
    SliceScratch& s = slice_scratch.local();
    for (int64_t k = r.begin(); k < r.end(); ++k) {
      const T* src = volume.voxels.data() + static_cast<size_t>(k) * slice_size;
      float* dst = result.voxels.data() + static_cast<size_t>(k) * slice_size;
      float* x_out = ky.radius > 0 ? s.slice.data() : dst;
      for (int64_t j = 0; j < ny; ++j) {
        const T* in = src + static_cast<size_t>(j) * row_size;
        float* out = x_out + static_cast<size_t>(j) * row_size;
        if (kx.radius == 0) {
          for (int64_t i = 0; i < nx; ++i) out[i] = static_cast<float>(in[i]);
          continue;
        }
        // The row with `outside` continuing on both ends (the ends were filled once).
        float* row = s.row.data() + kx.radius;
        for (int64_t i = 0; i < nx; ++i) row[i] = static_cast<float>(in[i]);
        convolve(kx, row, [row](int64_t t) { return row + t; }, nx, out);
      }
      if (ky.radius > 0) {
        const float* x_slice = s.slice.data();
        const float* beyond = s.outside.data();
        for (int64_t j = 0; j < ny; ++j) {
          auto row_at = [&](int64_t t) {
            const int64_t jj = j + t;
            return (jj < 0 || jj >= ny) ? beyond : x_slice + static_cast<size_t>(jj) * row_size;
          };
          convolve(ky, row_at(0), row_at, nx, dst + static_cast<size_t>(j) * row_size);
        }
      }
    }
    report(r.size());
  });

  if (kz.radius == 0) return result;

  // z pass, in place: copy a block of x-contiguous rows (one xz-plane, block_width columns, all z)
  // out of the result, then write each row back as the weighted sum of the copied rows around it.
  tbb::enumerable_thread_specific<BlockScratch> block_scratch([&] {
    BlockScratch s;
    s.block.resize(static_cast<size_t>(nz * block_width));
    s.outside.assign(static_cast<size_t>(block_width), outside);
    return s;
  });
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, z_blocks), [&](const tbb::blocked_range<int64_t>& r) {
    throw_if_cancelled(progress);
    BlockScratch& s = block_scratch.local();
    for (int64_t b = r.begin(); b < r.end(); ++b) {
      const int64_t j = b / blocks_per_plane;
      const int64_t x0 = (b % blocks_per_plane) * block_width;
      const int64_t width = std::min(block_width, nx - x0);
      float* column_base = result.voxels.data() + static_cast<size_t>(j) * row_size + x0;
      for (int64_t k = 0; k < nz; ++k) {
        const float* in = column_base + static_cast<size_t>(k) * slice_size;
        std::copy(in, in + width, s.block.data() + k * block_width);
      }
      for (int64_t k = 0; k < nz; ++k) {
        auto row_at = [&](int64_t t) {
          const int64_t kk = k + t;
          return (kk < 0 || kk >= nz) ? s.outside.data() : s.block.data() + kk * block_width;
        };
        convolve(kz, row_at(0), row_at, width, column_base + static_cast<size_t>(k) * slice_size);
      }
    }
    report(r.size());
  });
  return result;
}

template Volume<float> gaussian_filter(const Volume<uint8_t>&, double, float, Progress&);
template Volume<float> gaussian_filter(const Volume<int32_t>&, double, float, Progress&);
template Volume<float> gaussian_filter(const Volume<float>&, double, float, Progress&);

}  // namespace segmesh
