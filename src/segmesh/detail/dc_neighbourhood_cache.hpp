// The neighbourhood cache of Dual Contouring on a 0/1 field: each distinct neighbourhood key
// (dc_neighbourhood_keys.hpp) is solved once per thread, and a single-sheet cell once per mirror
// class of its key.
//
// The QEF of a cell of a 0/1 field is a function of its neighbourhood alone, and a surface has
// few distinct neighbourhoods (thousands among hundreds of thousands of cells), fewer still up to
// mirror images: the QEF, its solution and the cell's box all mirror with the cell (spacing and
// margins do not change), so a single-sheet cell is solved once per mirror class, in the frame
// of the class's smallest key, and mirrored back. Cells with two sheets are solved under their
// own key (which sheet is which would need mirroring too; they are rare). A thread's tables are
// kept by DcNeighbourhoods (dual_contouring.hpp) across the parts of a scene; only their own
// thread uses them, so nothing is locked, and a neighbourhood met by two threads is solved by
// both, with the same result: the output does not depend on the threads. (A table shared by the
// threads, filled by compare-and-swap, was tried: built anew for every part, it cost more in page
// faults and cache misses than the solves it shared saved; docs/PERFORMANCE.md.)
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "segmesh/detail/dc_key_table.hpp"
#include "segmesh/detail/dc_vertices.hpp"
#include "segmesh/dual_contouring.hpp"

namespace segmesh::dc {

// The sheet vertices of a cell with at most two sheets, as the cache keeps them (plain arrays:
// nothing to initialise for the cells that only read them): world offset from the cell's first
// corner (grid rotation and spacing applied, so a cell's vertex is its corner plus this). The
// offsets are float: a rounding of 1e-7 of the cell's size, far below the float positions' own,
// and half the bytes every cell's lookup reads.
struct SheetVertices {
  static constexpr int kPieces = 2;
  float offset[kPieces][3];
};
// Their world unit normals, kept apart: only read when vertex normals are asked for.
struct SheetNormals {
  float normal[SheetVertices::kPieces][3];
};

// A single sheet solved in its canonical neighbourhood's frame: index-space offset from the cell's
// first corner, and the sum of its crossings' unit normals before the grid's rotation.
struct CanonicalSheet {
  double offset[3];
  double normal_sum[3];
};

// One thread's solved neighbourhoods: `by_key` holds every key met (its vertices in its own frame,
// world normals), `by_class` the solved mirror classes.
struct SolvedNeighbourhoods {
  KeyTable<SheetVertices> by_key;
  std::vector<SheetNormals> normals;  // by_key's entries' normals, in its order (when asked for)
  KeyTable<CanonicalSheet> by_class;
};

// The entry of by_key for a cell with neighbourhood `key`, case cs and n (1 or 2) sheets:
// solved through its mirror class when it has one sheet, under its own key otherwise; its
// normals appended to table.normals when s.normals. `relevant`: relevant_points for the
// options' normal operator.
void solve_entry(const SheetSolve& s, const std::array<uint64_t, 256>& relevant,
                 SolvedNeighbourhoods& table, uint64_t key, int cs, int n, SheetVertices& out);

}  // namespace segmesh::dc

namespace segmesh {

struct DcNeighbourhoods::Tables {
  // What the entries are solved for: the cell's shape and rotation and the options that shape a
  // QEF vertex, and whether they keep vertex normals.
  std::array<double, 3> spacing;
  Mat3d direction;
  int connectivity;
  NormalMethod normals;
  double svd_eps;
  bool vertex_normals;
  tbb::enumerable_thread_specific<dc::SolvedNeighbourhoods> threads;  // made on first use

  bool fits(const Grid& g, const DcOptions& o) const {
    return g.spacing == spacing && g.direction == direction && o.connectivity == connectivity &&
           o.normals == normals && o.svd_eps == svd_eps && o.vertex_normals == vertex_normals;
  }
};

}  // namespace segmesh
