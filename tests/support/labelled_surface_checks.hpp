// Checks the multi-label extractors' tests share: what a LabelledSurface's outer boundary encloses,
// and that every part's shell is closed, manifold and wound outwards.
#pragma once

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "segmesh/components.hpp"
#include "segmesh/labelled_surface.hpp"
#include "segmesh/mesh_measures.hpp"
#include "segmesh/volume.hpp"
#include "support/test_fields.hpp"

namespace segmesh::test {

// A label map's components, all of them as parts, their surface and its shells.
struct ExtractedLabels {
  Components components;
  std::vector<size_t> parts;
  LabelledSurface surface;
  std::vector<TriMesh> shells;
};

// Two 4 x 6 x 6 voxel boxes, labels 1 and 2, touching across the plane x = 5.5.
inline LabelVolume two_touching_boxes() {
  LabelVolume v = blank_labels({12, 10, 10});
  for (int k = 2; k < 8; ++k)
    for (int j = 2; j < 8; ++j)
      for (int i = 2; i < 10; ++i) v.at(i, j, k) = i < 6 ? 1 : 2;
  return v;
}

// An 11 x 10 x 9 map whose inner voxels hold labels 0 .. labels at random: every junction kind
// (three and four materials on a face, diagonal pairs, cells of up to eight materials).
inline LabelVolume random_labels(std::mt19937& rng, int labels) {
  LabelVolume v = blank_labels({11, 10, 9});
  for (int64_t k = 1; k < 8; ++k)
    for (int64_t j = 1; j < 9; ++j)
      for (int64_t i = 1; i < 10; ++i) v.at(i, j, k) = int32_t(rng() % uint32_t(labels + 1));
  return v;
}

// extract(components, parts) makes the surface.
template <class Extract>
ExtractedLabels extract_labels(const LabelVolume& v, int connectivity, Extract&& extract) {
  ExtractedLabels x;
  x.components = find_components(v, {.connectivity = connectivity});
  for (size_t c = 0; c < x.components.components.size(); ++c) x.parts.push_back(c);
  x.surface = extract(x.components, x.parts);
  x.shells = part_shells(x.surface);
  return x;
}

// The volume inside the surface's outer boundary (its triangles against the background): what the
// parts' shells enclose together when every contact is shared (each counts once from each side).
inline double outer_volume(const LabelledSurface& surface) {
  TriMesh outer;
  outer.positions = surface.mesh.positions;
  for (size_t t = 0; t < surface.sides.size(); ++t) {
    const auto [in, out] = surface.sides[t];
    if ((in == 0) == (out == 0)) continue;
    const uint32_t* i = &surface.mesh.indices[3 * t];
    if (out == 0) {
      outer.indices.insert(outer.indices.end(), {i[0], i[1], i[2]});
    } else {
      outer.indices.insert(outer.indices.end(), {i[0], i[2], i[1]});
    }
  }
  return enclosed_volume(outer);
}

// Every shell closed (no boundary or non-manifold edge, consistent winding), without pinched
// vertices, enclosing a positive volume.
inline void expect_closed_shells(const ExtractedLabels& x, const std::string& what) {
  const std::vector<TriMesh>& shells = x.shells;
  ASSERT_EQ(shells.size(), x.parts.size()) << what;
  for (size_t p = 0; p < shells.size(); ++p) {
    const MeshMeasures m = measure_mesh(shells[p]);
    EXPECT_TRUE(m.closed()) << what << " part " << p << ": boundary " << m.boundary_edges
                            << ", non-manifold " << m.nonmanifold_edges << ", winding "
                            << m.winding_errors;
    EXPECT_EQ(m.nonmanifold_vertices, 0) << what << " part " << p;
    EXPECT_GT(m.volume_mm3, 0) << what << " part " << p;
  }
}

}  // namespace segmesh::test
