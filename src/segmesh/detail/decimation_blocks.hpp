// The blocks of decimation's block phase (decimation.cpp): a grid of cubes over the surface under
// decimation; a vertex is its block's core when every triangle around it lies in that block, and
// a block may collapse only edges whose ends and their neighbours are all its core, so blocks
// collapse side by side without touching the same data. Internal to the core: included by
// decimation.cpp only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "segmesh/detail/decimation_mesh.hpp"

namespace segmesh {

struct DecimationBlocks {
  static constexpr uint32_t kBorder =
      ~0u - 1;  // `core` of a vertex with a triangle in another block
  uint32_t count = 0;
  std::vector<uint32_t> core;  // per vertex: its block, or kBorder (dead vertices too)
  // count x materials: the shell sides (nonzero sides) of the triangles each block owns (every
  // corner in it: the only ones it can remove), by material.
  std::vector<int64_t> sides;
  // Per block: those of its owned sides whose triangle has two corners or more on or next to its
  // border (every edge of the triangle has an end with a neighbour outside the core: no collapse
  // of the phase removes it).
  std::vector<int64_t> locked;
  std::vector<std::vector<uint32_t>> vertices;  // per block: its core vertices, ascending
};

// The side of cubes that hold about `per_block` of the surface's vertices each (from its area);
// 0 when the surface has no area.
double decimation_block_side(const DecimationMesh& m, size_t per_block);

// The live surface's blocks: cubes of `side` millimetres, the grid shifted by `shift` sides from
// the surface's lowest corner. `count` is 0 (no blocks) when fewer than two cubes hold vertices
// or the grid or the table of sides would have more than `max_entries` entries.
DecimationBlocks decimation_blocks(const DecimationMesh& m, double side, double shift,
                                   size_t materials, size_t max_entries);

// Whether `block` may collapse edge (u, v): both and every vertex around them are its core.
// A core vertex's neighbours stay in its block (a collapse gives the kept vertex the removed
// one's neighbours, core by this rule), so what a block's collapse reads and writes (the
// vertices and triangles within two rings, the triangles around those: the checks, the
// witnesses, the lists) has every corner in the block, and no two blocks touch the same vertex,
// triangle or list.
bool in_block_core(const DecimationMesh& m, const std::vector<uint32_t>& core, uint32_t u,
                   uint32_t v, uint32_t block);

}  // namespace segmesh
