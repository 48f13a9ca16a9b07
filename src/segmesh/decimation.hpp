// Decimation: fewer triangles for the same shape, every part still closed, manifold and outward,
// contacts between parts still shared.
//
// Quadric-error edge collapse (Garland and Heckbert, "Surface simplification using quadric error
// metrics", SIGGRAPH 1997) on a LabelledSurface (labelled_surface.hpp), so one code path serves
// conforming scenes (one surface of all parts: a contact is decimated once, for both parts) and
// independent ones (each part's mesh a surface of one part against the background).
//
// Quadrics (detail/quadric.hpp). Every triangle's plane (unit normal, weight 1/3) is added to
// its three corners, so each plane counts once over the surface; a collapse adds the two
// quadrics. The root of the quadric at a point, a root-sum-square of distances to planes of the
// original surface near it, is the collapse's cost and, with `error_mm`, its limit (three
// quarters of it: the flips may take the last quarter). Planes are not triangles, so with
// `error_mm` every original vertex also keeps a witness, a live triangle within that limit; a
// collapse whose changed triangles leave an original vertex without a new witness among its
// vertex's triangles is refused. That bounds the distance from the original vertices to the
// result; the other direction rests on the quadrics, so scene reports measure the true distance
// both ways (scene_measures.hpp).
//
// Vertex roles (detail/surface_roles.hpp) constrain every collapse, so the junction curves and
// the interfaces keep their topology:
//   - a sheet vertex (one interface) collapses into a neighbour, which shares that interface;
//     into a sheet neighbour at the quadric's optimum (the endpoint or midpoint of least error
//     when the quadric is singular or its optimum lies far from the edge), into a curve or fixed
//     neighbour at that neighbour's position;
//   - a curve vertex collapses only along its junction curve (an edge whose triangles separate
//     two or more different pairs of materials): into a curve neighbour at the optimum on the
//     segment between the two, into a fixed neighbour at its position;
//   - fixed vertices (where curves meet or end) never move or vanish.
// A vertex that absorbs one of the surface's junction_vertices (where a part's shell may touch
// itself) becomes one, so part_shells still splits the shells there.
// A collapse is refused when it would
//   - break the link condition on the shared surface (the two vertices' common neighbours must
//     be exactly the apexes of the triangles on the edge) or in any part's shell (the same on the
//     part's triangles; and two vertices of one shell never merge without an edge of that shell
//     between them), so every shell stays an edge-manifold closed surface;
//   - turn any remaining triangle's normal by more than 60 degrees, or make it degenerate;
//   - make a triangle with radii ratio below 0.02 where the neighbourhood had none as bad (at
//     0.05 the phantom decimated 4.5 times instead of 8 at 0.2 mm; the flips mend most);
//   - where the triangles within two rings of the edge belong to more than one interface, make a
//     triangle around the merged vertex cross one of them (a sheet folded through another
//     part's; segment_crosses_triangle of detail/fold_repair.hpp);
//   - bring any part below `min_part_triangles` (32: a screw stays an elongated solid with its
//     thread's outline and does not shrink toward a tetrahedron; the shells' topology checks need
//     more than four vertices anyway).
// Stop: with `error_mm` alone, when the cheapest collapse costs more; with a budget, a collapse
// more expensive than `error_mm` is still made while the budget is exceeded ("the budget wins"),
// until no collapse is possible. On a conforming scene (one surface) the scene's budget is the
// surface's: the shells' triangles together, collapsed cheapest first over all parts, so the
// error evens out between them; on independent surfaces (each part alone, in parallel) every part
// gets the share of its area (part_triangle_budgets). The per-part budget holds for each part on
// both.
//
// Afterwards up to four rounds improve the triangles' shape, each keeping every witness: a pass
// of edge flips and one of tangential relaxation (detail/decimation_passes.hpp), and a pass that
// collapses an edge of every sliver (radii ratio below 0.05) when the collapse's cost is within
// the bound and its checks pass. With `error_mm`, a flip or a move is also refused when a point
// it makes (a new triangle's centroid, a new edge's midpoint, the moved vertex) lies farther than
// the witnesses' share of the bound from the undecimated surface (an exact search in a tree on a
// copy of it): the witnesses bound only the other direction, and these passes, unlike a
// collapse, have no quadric that keeps the new triangles near the old surface. A flip that
// removes a sliver may then move the surface by the whole bound, when the original triangles
// under the quad (corners, edge midpoints, centroids) also stay within it: on the phantom at
// 0.2 mm that left 41 slivers instead of 270.
//
// Order: first a block phase on all threads (`blocks` below), then the rest cheapest first on
// one. The block phase (surfaces of 32 768 vertices or more) lays a grid of cubes over the
// surface, each holding about 16 384 vertices (detail/decimation_blocks.hpp). A vertex whose
// triangles all lie in its cube is that block's core; a block collapses only edges whose two
// ends and all their neighbours are its core, so what one collapse reads and writes lies in its
// block, and the blocks run side by side, each cheapest first from its own buckets, each keeping
// its own parts above the minimum. Without a budget every block goes to the end of the error bound
// at once. With one budget for the surface (the scene's on a conforming surface, a part's on an
// independent one), the blocks go in rounds of one cost bucket (4.4 % of an octave) together,
// and beyond the error bound each may remove its share (by the triangles it can remove) of the
// triangles above 1.25 times the blocks' share of the budget; they stop at 1.5 times it. The
// phase runs twice, the second grid shifted by half a cube so that the first one's borders lie
// inside its blocks, and beyond the error bound only up to the cost the first reached. The
// loop over the whole surface then takes what is left (collapses along the borders, and a
// budget's last collapses, so a budget ends in one cheapest-first order over the whole
// surface), by octaves of cost, each octave swept in vertex order so the checks read memory in
// the order the surface is stored (an octave a budget may stop in keeps buckets 4.4 % wide, as
// does a surface small enough for the cache throughout; detail/decimation_order.hpp).
// Deterministic: the blocks, their rounds and their order do not depend on the threads, so
// neither does the result.
// Cost: O(T) bucket operations for T triangles plus the checks, a few hundred bytes per vertex.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "segmesh/labelled_surface.hpp"

namespace segmesh {

struct Scene;

struct DecimateOptions {
  double error_mm = 0;                 // > 0: collapse while the quadric error stays below
  int64_t max_triangles = 0;           // > 0: the scene's budget (see "Stop" above)
  int64_t max_triangles_per_part = 0;  // > 0: every part's budget
  // The block phase before the cheapest-first loop ("Order" above), on by default; off: the
  // loop alone (for comparisons and tests).
  enum class Blocks { kOn, kOff };
  Blocks blocks = Blocks::kOn;
  bool active() const { return error_mm > 0 || max_triangles > 0 || max_triangles_per_part > 0; }
};

inline constexpr int64_t kMinPartTriangles = 32;

// The first problem with the options, naming the field's command-line option, or nothing.
struct DecimateOptionsProblem {
  std::string_view option;  // "decimate-error"
  std::string_view rule;    // "must be a non-negative number of millimetres"
};
std::optional<DecimateOptionsProblem> decimate_options_problem(const DecimateOptions& options);

// Every part's triangle budget (0: none): the scene's budget shared in proportion to the parts'
// areas, each share at least kMinPartTriangles and the shares together within the budget (when
// the minimum allows), and the per-part budget, whichever is smaller.
std::vector<int64_t> part_triangle_budgets(const std::vector<double>& part_areas_mm2,
                                           const DecimateOptions& options);

struct DecimationStats {
  int64_t collapses = 0;
  int64_t flips = 0;
  int64_t relaxed = 0;  // vertex moves of the tangential relaxation
  double largest_cost_mm = 0;  // the largest quadric error of a collapse made
};

// Decimates the surface in place (vertices renumbered, junction_vertices kept, normals and
// colours cleared). `budgets` holds one budget per part (0: none); `surface_budget` (0: none) one
// for the triangles of all parts' shells together (a contact's triangle counts in both shells).
DecimationStats decimate_surface(LabelledSurface& surface, const DecimateOptions& options,
                                 std::span<const int64_t> budgets, int64_t surface_budget = 0);

// The decimation step of the pipeline: the scene's surface (shells cut again) or every part's
// mesh, each part's normals recomputed. Nothing when the options are not active.
DecimationStats decimate_scene(Scene& scene, const DecimateOptions& options);

}  // namespace segmesh
