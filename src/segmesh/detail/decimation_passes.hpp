// The passes that make a decimated surface's triangles better (decimation.hpp), on the working
// state of detail/decimation_mesh.hpp; decimation.cpp runs them in turn after the collapses.
// Neither moves a curve or fixed vertex or changes a junction curve's edges, both keep every
// original vertex's witness within the bound `limit2` (squared; infinity: kept alive only), and
// with an error bound both keep the points they make (a flip's new triangles' centroids and its
// new edge's midpoint, a moved vertex, its edges' midpoints and its triangles' centroids) within
// sqrt(limit2) of the surface as it was before decimation (DecimationMesh::near_original): the
// witnesses bound only the distance from the original surface, and nothing else keeps these
// passes' triangles near it.
// Serial and deterministic: vertices and triangles in id order.
#pragma once

#include <cstdint>

#include "segmesh/detail/decimation_mesh.hpp"

namespace segmesh {

// One pass of edge flips over the live triangles: an edge between two triangles of one
// interface (either winding; no other triangle on it, so never a junction curve's edge)
// becomes the other diagonal of its quad when the smaller radii ratio of the two grows, the
// other diagonal is not an edge already (no shell gets a doubled edge), neither new triangle
// turns more than 60 degrees from the quad's normal, the surface moves at most `tolerance`
// (the height of the tetrahedron of the two diagonals; when the flip removes a sliver, radii
// ratio below 0.05, at most `bound` with an error bound, else `bound` less the largest quadric
// error of the quad's corners, if that is more), the new points stay near the original surface,
// every original vertex whose witness was one of the two finds a new one within the bound, and,
// for a flip that moves the surface more than `tolerance`, the original triangles near the quad
// (their corners, edge midpoints and centroids) that were within the bound of the quad stay
// within it. A flip changes both sides of a contact alike and moves no vertex.
// Returns the flips made.
int64_t flip_pass(DecimationMesh& m, double tolerance, double bound, double limit2);

// One pass of tangential relaxation over the sheet vertices whose neighbours are all sheet
// vertices (so every triangle within two rings is of one interface and a move crosses
// nothing): each moves toward its neighbours' centroid within its tangent plane when that
// makes the worst triangle around it better (or their mean, the worst kept at 0.3
// or where it was), turns no triangle by more than 30 degrees, keeps the quadric within
// `bound` (or where it was), keeps the new points near the original surface and leaves every
// original vertex a witness.
// Returns the vertices moved.
int64_t relax_pass(DecimationMesh& m, double bound, double limit2);

}  // namespace segmesh
