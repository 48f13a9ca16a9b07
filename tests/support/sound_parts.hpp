// The tests' check that every part of a scene is one closed, edge- and vertex-manifold,
// consistently wound, outward shell with a normal per vertex.
#pragma once

#include <gtest/gtest.h>

#include "segmesh/mesh_measures.hpp"
#include "segmesh/scene.hpp"

namespace segmesh::test {

inline void expect_sound_shells(const Scene& scene) {
  for (const Part& part : scene.parts) {
    const MeshMeasures m = measure_mesh(part.mesh);
    EXPECT_TRUE(m.closed()) << part.name;
    EXPECT_EQ(m.nonmanifold_edges, 0) << part.name;
    EXPECT_EQ(m.nonmanifold_vertices, 0) << part.name;
    EXPECT_EQ(m.winding_errors, 0) << part.name;
    EXPECT_EQ(m.shells, 1) << part.name;
    EXPECT_GT(m.volume_mm3, 0) << part.name;  // outward
    EXPECT_EQ(part.mesh.normals.size(), part.mesh.positions.size()) << part.name;
  }
}

}  // namespace segmesh::test
