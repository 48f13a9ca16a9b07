// Dual Contouring's polygons: the sheets around a cut edge in order, and their triangles.
//
// Every cut edge gets the polygon of the sheets of its four cells around it, wound
// counter-clockwise seen from outside: a quad, or up to twelve vertices where a cell holds several
// sheets at that edge. A quad is split along the diagonal that gives the better radii ratios
// (split_quads, four quads at a time); a larger polygon is triangulated by dynamic programming
// over the diagonals that keep the mesh manifold, or, where none does, fanned around a new vertex
// at its centroid.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/tri_mesh.hpp"

namespace segmesh::dc {

// The four cells around an edge along axis a, counter-clockwise seen from +a: their offsets along
// u = (a + 1) % 3 and v = (a + 2) % 3 from the edge's grid point, and whether the cell's pieces
// around the edge run from its u-face to its v-face (entering by the u-face) or the reverse.
inline constexpr int kQuadrantDu[4] = {0, 0, -1, -1};
inline constexpr int kQuadrantDv[4] = {-1, 0, 0, -1};
inline constexpr bool kQuadrantForward[4] = {true, false, true, false};

// The cell edge (marching_cubes_table.hpp numbering) along `axis` at cell coordinates (cu, cv)
// along u and v; the cell of quadrant q holds the edge as local_edge(axis, -kQuadrantDu[q],
// -kQuadrantDv[q]).
constexpr int local_edge(int axis, int cu, int cv) {
  return axis * 4 + (axis == 1 ? cv + 2 * cu : cu + 2 * cv);
}

inline constexpr int kMaxPolygon = 12;

// The first n entries are set (the rest stays uninitialised: one is made per cut edge).
struct Polygon {
  int n = 0;
  std::array<uint32_t, kMaxPolygon> vertex;
  std::array<int, kMaxPolygon> quadrant;
};

// A cell around a cut edge as polygon() needs it: its first sheet vertex and its case, or
// kOneSheet for a cell known to hold a single sheet (whose vertex is then its first).
inline constexpr int kOneSheet = -1;
struct CellRef {
  int cs = kOneSheet;
  uint32_t first_vertex = 0;
};

// The polygon of the sheets around an edge along `axis` from its four cells (kQuadrantDu /
// kQuadrantDv order), wound counter-clockwise seen from outside; `mirrored`: the grid's
// direction mirrors, which flips every winding once more.
Polygon polygon(const DcTable& table, int axis, const std::array<CellRef, 4>& quadrant,
                bool inside_at_start, bool mirrored);

// Polygon diagonals may only join sheets of the two cells that share nothing but the edge: any
// other pair may already be joined by an edge of the mesh, and a second one would be non-manifold.
inline bool diagonal_allowed(const Polygon& p, int i, int j) {
  if ((j - i + p.n) % p.n == 1 || (i - j + p.n) % p.n == 1) return true;
  return (p.quadrant[i] - p.quadrant[j] + 4) % 4 == 2;
}

// Best triangulation under diagonal_allowed by dynamic programming over sub-polygons: the worst
// radii ratio first, then the sum. Returns false when none exists. `rho(i, j, k)` scores a triangle.
template <class Score>
bool triangulate(const Polygon& p, Score&& rho, std::vector<std::array<int, 3>>& out) {
  const int n = p.n;
  struct Best {
    double min = -1, sum = 0;
    int split = -1;
  };
  std::array<std::array<Best, kMaxPolygon>, kMaxPolygon> best{};
  for (int i = 0; i + 1 < n; ++i) best[i][i + 1] = {std::numeric_limits<double>::infinity(), 0, -2};
  for (int len = 2; len < n; ++len) {
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      if (!diagonal_allowed(p, i, j)) continue;
      for (int k = i + 1; k < j; ++k) {
        const Best& a = best[i][k];
        const Best& b = best[k][j];
        if (a.split == -1 || b.split == -1) continue;
        const double r = rho(i, k, j);
        const double mn = std::min({a.min, b.min, r});
        const double sum = a.sum + b.sum + r;
        Best& cur = best[i][j];
        if (cur.split == -1 || mn > cur.min + 1e-12 || (mn > cur.min - 1e-12 && sum > cur.sum + 1e-12)) {
          cur = {mn, sum, k};
        }
      }
    }
  }
  if (best[0][n - 1].split == -1) return false;
  out.clear();
  std::array<std::pair<int, int>, kMaxPolygon> stack;
  int top = 0;
  stack[top++] = {0, n - 1};
  while (top > 0) {
    const auto [i, j] = stack[--top];
    if (j - i < 2) continue;
    const int k = best[i][j].split;
    out.push_back({i, k, j});
    stack[top++] = {i, k};
    stack[top++] = {k, j};
  }
  return true;
}

// Triangles (and centroid vertices, 0 or 1) a polygon becomes.
std::pair<uint64_t, uint64_t> polygon_cost(const Polygon& p);

// Writes the triangles of a polygon that is not a quad at `out` (polygon_cost(p).first of them)
// and returns the end; where it needs a centroid vertex, that is vertex `extra` of the mesh
// (positions, and normals when it has them), and `extra` moves on by one. `scratch` is reused
// between calls.
uint32_t* write_polygon(const Polygon& p, TriMesh& mesh, uint32_t& extra, uint32_t* out,
                        std::vector<std::array<int, 3>>& scratch);

// A quad whose two triangles are written once its diagonal is chosen.
struct PendingQuad {
  uint32_t* out;   // six indices
  uint32_t v[4];   // its vertices in polygon() order
};

// Splits each of n quads along the diagonal that gives the better worst radii ratio (by more
// than 1e-6; the first otherwise) and writes its triangles. With SSE2 four quads at a time, one
// per lane: the same IEEE operations on the same operands in the same order, so the same choice.
void split_quads(const Vec3f* positions, const PendingQuad* quads, size_t n);

}  // namespace segmesh::dc
