// Fields the extraction tests are run on: padded 0/1 patterns, random label maps and analytic
// shapes sampled on anisotropic, rotated grids; and the exact comparison of two meshes.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "segmesh/image.hpp"
#include "segmesh/tri_mesh.hpp"
#include "segmesh/volume.hpp"

namespace segmesh::test {

// A label map as the pipeline's input, as read from a uint8 file named `path` (error messages
// name it).
inline Image label_image(LabelVolume v, std::string path = "test.nii.gz") {
  Image image;
  image.path = std::move(path);
  image.voxel_type = "uint8";
  image.volume = std::move(v);
  return image;
}

// A label map of background only: `dims` voxels of `spacing` mm.
inline LabelVolume blank_labels(std::array<int64_t, 3> dims, std::array<double, 3> spacing = {1, 1, 1}) {
  LabelVolume v;
  v.grid.dims = dims;
  v.grid.spacing = spacing;
  v.voxels.assign(v.grid.voxel_count(), 0);
  return v;
}

// Sets the voxels lo <= (i, j, k) < hi to `label`: a box of voxels.
inline void fill_box(LabelVolume& v, std::array<int64_t, 3> lo, std::array<int64_t, 3> hi, int32_t label) {
  for (int64_t k = lo[2]; k < hi[2]; ++k)
    for (int64_t j = lo[1]; j < hi[1]; ++j)
      for (int64_t i = lo[0]; i < hi[0]; ++i) v.at(i, j, k) = label;
}

// A label map of random voxels: each filled with probability `density`, with a label drawn from
// 1 .. labels; parts touch the volume's border.
inline LabelVolume random_labels(std::array<int64_t, 3> dims, int labels, double density, unsigned seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution filled(density);
  std::uniform_int_distribution<int> label(1, labels);
  LabelVolume v;
  v.grid.dims = dims;
  v.voxels.resize(v.grid.voxel_count());
  for (auto& x : v.voxels) x = filled(rng) ? label(rng) : 0;
  return v;
}

// The same triangles on bit-identical positions and normals.
inline bool identical(const TriMesh& a, const TriMesh& b) {
  // Bitwise (a NaN equals itself; -0 and 0 differ); empty arrays may have no data pointer.
  auto same = [](const std::vector<Vec3f>& x, const std::vector<Vec3f>& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(Vec3f)) == 0);
  };
  return a.indices == b.indices && same(a.positions, b.positions) && same(a.normals, b.normals);
}

// A binary field with `pad` background voxels around the given inside pattern.
inline Volume<uint8_t> padded(const std::array<int64_t, 3>& dims, const std::vector<uint8_t>& inside,
                       int pad = 1) {
  Volume<uint8_t> v;
  v.grid.dims = {dims[0] + 2 * pad, dims[1] + 2 * pad, dims[2] + 2 * pad};
  v.voxels.assign(v.grid.voxel_count(), 0);
  for (int64_t k = 0; k < dims[2]; ++k)
    for (int64_t j = 0; j < dims[1]; ++j)
      for (int64_t i = 0; i < dims[0]; ++i)
        v.at(i + pad, j + pad, k + pad) = inside[(k * dims[1] + j) * dims[0] + i];
  return v;
}

// A padded field whose inside voxels are drawn by fair coin flips (seeded): Marching Cubes makes
// a closed manifold mesh of many small pieces from it, numbered plane by plane.
inline Volume<uint8_t> random_coins(const std::array<int64_t, 3>& dims, unsigned seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution coin(0.5);
  std::vector<uint8_t> inside(static_cast<size_t>(dims[0] * dims[1] * dims[2]));
  for (auto& v : inside) v = coin(rng);
  return padded(dims, inside);
}

// A signed field sampled on an anisotropic grid: value = shape(world point), inside positive.
template <class F>
Volume<float> sample(const Grid& grid, F&& shape) {
  Volume<float> v;
  v.grid = grid;
  v.voxels.resize(grid.voxel_count());
  for (int64_t k = 0; k < grid.dims[2]; ++k)
    for (int64_t j = 0; j < grid.dims[1]; ++j)
      for (int64_t i = 0; i < grid.dims[0]; ++i)
        v.at(i, j, k) = static_cast<float>(shape(grid.to_world({double(i), double(j), double(k)})));
  return v;
}

inline Grid anisotropic_grid(double extent, Mat3d direction = identity3()) {
  Grid g;
  g.spacing = {0.25, 0.3, 0.45};
  g.direction = direction;
  for (int a = 0; a < 3; ++a) g.dims[a] = static_cast<int64_t>(2 * extent / g.spacing[a]) + 1;
  // Centre the grid on the world origin.
  const Vec3d half = g.to_world({double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2,
                                 double(g.dims[2] - 1) / 2});
  g.origin = {-half.x, -half.y, -half.z};
  return g;
}

}  // namespace segmesh::test
