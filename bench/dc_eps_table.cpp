// Mean radii ratio of Dual Contouring for a range of QEF singular-value cut-offs (--dc-svd-eps),
// with central and Sobel normals, against Marching Cubes: how the default was chosen
// (docs/DUAL_CONTOURING.md). Every component of 1000 voxels or more of every label.
//   segmesh_dc_eps_table LABELMAP
#include <cstdio>

#include "segmesh/component_field.hpp"
#include "segmesh/components.hpp"
#include "segmesh/dual_contouring.hpp"
#include "segmesh/marching_cubes.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/quality.hpp"
#include "segmesh_io/read_volume.hpp"

using namespace segmesh;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: segmesh_dc_eps_table LABELMAP\n");
    return 2;
  }
  const Image image = read_volume(argv[1]);
  const LabelVolume labels = image.labels_int32();
  const Components comps = find_components(labels, {});
  auto score = [&](auto&& extract) {
    double rho_sum = 0, volume = 0, voxels = 0;
    int64_t triangles = 0;
    for (const Component& c : comps.components) {
      if (c.voxels < 1000) continue;
      const TriMesh m = extract(component_mask(labels.grid, comps, c));
      const QualityStats q = triangle_quality(m);
      rho_sum += q.mean * double(q.triangles);
      triangles += q.triangles;
      volume += measure_mesh(m).volume_mm3;
      voxels += double(c.voxels) * labels.grid.voxel_volume();
    }
    std::printf(" %.3f (volume %+.3f %%) |", rho_sum / double(triangles), 100 * (volume - voxels) / voxels);
  };
  std::printf("| normals | 0.001 | 0.05 | 0.1 | 0.2 | 0.5 | 1.0 | Marching Cubes |\n| --- |");
  for (int i = 0; i < 7; ++i) std::printf(" ---: |");
  std::printf("\n");
  for (NormalMethod normals : {NormalMethod::central, NormalMethod::sobel}) {
    std::printf("| %s |", normals == NormalMethod::sobel ? "sobel" : "central");
    for (double eps : {0.001, 0.05, 0.1, 0.2, 0.5, 1.0}) {
      score([&](const auto& f) { return dual_contouring(f, {.normals = normals, .svd_eps = eps}); });
    }
    score([&](const auto& f) { return marching_cubes(f, {.normals = normals}); });
    std::printf("\n");
  }
}
