// How far a mesh moved when its vertices moved and its triangles stayed: a mesh and its smoothed
// copy. The numbers are mesh_deviation's (mesh_distance.hpp): samples at the vertices used by a
// triangle and at every triangle's centroid, on both meshes, each measured against the other
// mesh; Hausdorff (largest), mean and 95th percentile over the samples of both directions.
//
// What makes it cheap, where mesh_deviation indexes two arbitrary meshes:
// - The index (detail/ordered_triangle_tree.hpp). The triangles keep the order extraction gave
//   them (row by row, plane by plane), so runs of consecutive triangles are already compact in
//   space: the tree's leaves are such runs, built in one pass with no sort and no copy. On
//   make_big.py's 5.2 M triangle bone both trees take about 70 ms where MeshDistance's
//   median-split tree with oriented boxes takes 2.5 s for one (docs/PERFORMANCE.md).
// - The bound. Every sample has a counterpart on the other mesh (the same vertex, the same
//   triangle's centroid) whose distance bounds its own, and a triangle at that distance: the
//   search starts with the leaf holding that triangle, which usually holds the closest one too,
//   and then looks only at leaves nearer than the best distance so far. When every sample is
//   measured, or every few (a stride up to 16), samples are searched in groups of 16 (close
//   together, as the samples follow the vertex and triangle order): one walk down the tree finds
//   the leaves near the whole group (16 % faster than a walk per sample on the phantom), and a
//   leaf's triangle boxes are made once for all of them.
// - The sample count. The mean and the 95th percentile are statistics of the sample distribution:
//   above `statistic_samples` samples in one direction they are taken over a stratified subset
//   of about that many: one sample in every stratum of `stride` consecutive ids (neighbours on
//   the surface), at a fixed pseudo-random place in it, the same for any thread count and both
//   directions. At 2^16 the estimates are within 0.4 % of the full ones on every part of the
//   phantom and on make_big.py's bone (7.8 M samples a direction), and within 1 % on the
//   test-size phantom (a test); docs/PERFORMANCE.md. The Hausdorff distance is not a statistic:
//   it stays the exact largest over every sample of both directions. Each unmeasured sample's
//   counterpart distance bounds its own in both directions, so only samples whose bound exceeds
//   the largest distance found are searched, both ways: the 1024 largest bounds first, to raise
//   it early, then the rest still above it, each search ending at the first triangle or corner
//   within the largest distance (most end in their start leaf). Below the limit every sample is
//   measured and every number equals mesh_deviation's up to the rounding of the sums.
//
// Memory: the tree (about 3 bytes per triangle), one triangle id per vertex, and the measured
// distances in double (at most statistic_samples per direction).
#pragma once

#include <cstddef>
#include <vector>

#include "segmesh/mesh_distance.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh {

inline constexpr size_t kDeviationStatisticSamples = size_t{1} << 16;

// The deviation between the surface with `before` as positions and after.indices as triangles,
// and `after`. Preconditions: before.size() == after.positions.size(), every index in range,
// finite positions. Parallel; the result does not depend on the number of threads.
Deviation moved_mesh_deviation(const std::vector<Vec3f>& before, const TriMesh& after,
                               size_t statistic_samples = kDeviationStatisticSamples);

}  // namespace segmesh
