// Gaussian smoothing of a volume: the optional "pre-smoothing" of a part's field before surface
// extraction.
//
// Why: a binary label map carries no sub-voxel information. Marching Cubes on a 0/1 indicator puts
// every vertex at an edge midpoint and every normal on a handful of directions, so smooth anatomy
// comes out terraced. Smoothing the indicator (or a grey-value field) first turns the step into a
// ramp whose 0.5 iso-surface has sub-voxel position and continuous normals.
// The price is volume and detail:
//   - a flat surface stays where it is (the 0.5 level of a smoothed step is at the step), but a
//     curved one moves towards its centre of curvature: the 0.5 iso-surface moves inwards by about
//     sigma^2 * H, H the mean curvature ((k1 + k2) / 2, positive where convex). A ball of radius R
//     shrinks to about R - sigma^2 / R and loses about 3 sigma^2 / R^2 of its volume (0.75 % for
//     R = 20 sigma). Convex parts lose volume; holes and notches fill in.
//   - a structure thinner than about 2 sigma is flattened below 0.5 and can vanish entirely: in
//     the continuum a slab's peak drops below 0.5 under a thickness of 1.35 sigma
//     (erf(w / (2 sqrt(2) sigma)) = 0.5), a rod's under a diameter of 2.35 sigma, a ball's under
//     3.1 sigma; sampling on the grid makes it a little worse. Long before vanishing, thin parts
//     lose a large share of their volume: at sigma = 1 voxel a 40 x 40 x 2-voxel slab loses about
//     19 %, a ball of radius 20 voxels 0.9 % (of its voxel count). Thin cortical bone and narrow
//     gaps between parts are the first casualties: keep sigma below half the thinnest structure
//     that must survive.
//
// What: a separable Gaussian of standard deviation sigma_mm millimetres, the same physical width on
// every axis; in voxels it is sigma_mm / spacing[a] on axis a, so an anisotropic CT gets fewer taps
// along its coarse axis. The sampled kernel is truncated at ceil(3 sigma) voxels and normalised to
// sum 1 per axis (a constant stays constant, mass is preserved where the kernel fits). An axis whose
// sigma is below kGaussianMinSigmaVoxels voxels is left alone (its kernel would be the identity to
// float precision). Outside the volume the value `outside` continues: the caller's field is padded
// with background, so smoothing sees background beyond the crop as well.
//
// How: three passes, x, y, z. The x and y passes run together per z-slice (a slice-sized buffer per
// worker), the z pass per block of x-contiguous rows of one xz-plane, in place on the output (a
// block-sized buffer per worker). Every inner loop runs along x over contiguous memory, so the y and
// z passes stream whole rows instead of striding down single columns. Parallel with oneTBB over
// slices and row blocks; every output value is computed by the same sequence of float operations
// whatever the partition, so the result is identical for any thread count. Progress is updated and
// cancellation checked once per slice or block.
//
// [in]  volume    voxels on a Grid (uint8_t, int32_t or float)
// [in]  sigma_mm  standard deviation in millimetres; <= 0 (or NaN) returns the input as float
// [in]  outside   the value assumed beyond the volume on every side
// [out] a float volume on the same Grid
// Cost: O(voxels x taps) time, taps = sum over the axes of 2 ceil(3 sigma / spacing) + 1; memory:
// the output plus one slice (x-y passes) or one block of rows (z pass) per worker.
#pragma once

#include <array>
#include <cstdint>

#include "segmesh/progress.hpp"
#include "segmesh/volume.hpp"

namespace segmesh {

// An axis whose sigma in voxels is below this is not filtered: the neighbours' weight would be
// exp(-1 / (2 * 0.1^2)) ~ 2e-22 of the centre's.
inline constexpr double kGaussianMinSigmaVoxels = 0.1;

template <class T>
Volume<float> gaussian_filter(const Volume<T>& volume, double sigma_mm, float outside = 0.0f,
                              Progress& progress = null_progress());

extern template Volume<float> gaussian_filter(const Volume<uint8_t>&, double, float, Progress&);
extern template Volume<float> gaussian_filter(const Volume<int32_t>&, double, float, Progress&);
extern template Volume<float> gaussian_filter(const Volume<float>&, double, float, Progress&);

// The kernel radius in voxels per axis: ceil(3 sigma_mm / spacing[a]), 0 for sigma_mm <= 0.
std::array<int64_t, 3> gaussian_radius(const Grid& grid, double sigma_mm);

// The margin (voxels per axis) a field needs around its content so that smoothing does not reach
// the field's border: the kernel radius plus kFieldMargin (2) voxels, which stay pure background
// after smoothing and so keep the field's closed-surface and exact-gradient guarantees.
std::array<int64_t, 3> gaussian_margin(const Grid& grid, double sigma_mm);

}  // namespace segmesh
