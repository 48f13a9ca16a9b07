#include "segmesh/detail/dc_polygon_pass.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <type_traits>
#include <vector>

#include "segmesh/detail/dc_owned_edges.hpp"

namespace segmesh::dc {

void count_polygons(CellRows& c, bool mirrored, Progress& progress) {
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, c.rows(), 256), [&](const auto& range) {
    throw_if_cancelled(progress);
    for (int64_t r = range.begin(); r < range.end(); ++r) {
      const int64_t j = r % c.cy, k = r / c.cy;
      if (c.row_short[size_t(r)]) {
        owned_edges<Edges::all_checked>(
            c, j, k, [](int, const auto&, bool) {});  // throws for the cut edge at fault
      }
      bool rare = false;
      for (int q = 0; q < 4; ++q) {
        const int64_t jr = j + (q & 1), kr = k + (q >> 1);
        rare = rare || (jr < c.cy && kr < c.cz && c.row_rare[c.row_index(jr, kr)]);
      }
      if (!rare) continue;
      uint64_t triangles = c.triangle_first[size_t(r) + 1], extra = 0;
      owned_edges<Edges::next_to_rare>(c, j, k, [&](int axis, const auto& quadrant, bool in) {
        const auto [t, e] = polygon_cost(polygon(c.table, axis, quadrant, in, mirrored));
        triangles += t - 2;  // a polygon has four vertices or more
        extra += e;
      });
      c.triangle_first[size_t(r) + 1] = count32(triangles);
      c.extra_first[size_t(r) + 1] = count32(extra);
    }
  });
}

void emit_polygons(const CellRows& c, bool mirrored, TriMesh& mesh, Progress& progress) {
  std::atomic<int64_t> rows_done{0};
  const uint64_t sheets = c.sheets();
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, c.rows(), 64), [&](const auto& range) {
    throw_if_cancelled(progress);
    std::vector<std::array<int, 3>> tris;
    // The quads waiting for their diagonals, split a few hundred at a time: a fixed array filled
    // by an inlined visitor keeps the per-quad bookkeeping to a store.
    std::array<PendingQuad, 512> quads;
    size_t pending = 0;
    for (int64_t r = range.begin(); r < range.end(); ++r) {
      if (c.triangle_first[size_t(r) + 1] == c.triangle_first[size_t(r)]) continue;
      uint32_t* out = mesh.indices.data() + 3 * size_t{c.triangle_first[size_t(r)]};
      uint32_t extra = static_cast<uint32_t>(sheets + c.extra_first[size_t(r)]);
      // A quad waiting for its diagonal; split_quads writes its six indices. Always inlined: the
      // pass's hot path.
      auto quad = [&](const uint32_t* q4) __attribute__((always_inline)) {
        if (pending == quads.size()) {
          split_quads(mesh.positions.data(), quads.data(), pending);
          pending = 0;
        }
        quads[pending++] = {out, {q4[0], q4[1], q4[2], q4[3]}};
        out += 6;
      };
      // A polygon next to a rare cell (not inlined: a few per row at most).
      auto any_polygon = [&](int axis, const std::array<CellRef, 4>& quadrant, bool in)
          __attribute__((noinline)) {
        const Polygon p = polygon(c.table, axis, quadrant, in, mirrored);
        if (p.n == 4) {
          quad(p.vertex.data());
          return;
        }
        out = write_polygon(p, mesh, extra, out, tris);
      };
      const int64_t j = r % c.cy, k = r / c.cy;
      owned_edges<Edges::all>(
          c, j, k, [&](int axis, const auto& quadrant, bool in) __attribute__((always_inline)) {
            const bool reverse = in == mirrored;  // polygon()'s winding, for a quad inline
            uint32_t q4[4];
            if constexpr (std::is_same_v<std::decay_t<decltype(quadrant)>,
                                         std::array<uint32_t, 4>>) {
              for (int n = 0; n < 4; ++n) q4[n] = quadrant[reverse ? 3 - n : n];
              quad(q4);
            } else if (quadrant[0].cs == kOneSheet && quadrant[1].cs == kOneSheet &&
                       quadrant[2].cs == kOneSheet && quadrant[3].cs == kOneSheet) {
              for (int n = 0; n < 4; ++n) q4[n] = quadrant[reverse ? 3 - n : n].first_vertex;
              quad(q4);
            } else {
              any_polygon(axis, quadrant, in);
            }
          });
    }
    split_quads(mesh.positions.data(), quads.data(), pending);
    progress.update(0.5 + 0.5 * double(rows_done += range.size()) / double(c.rows()));
  });
}

}  // namespace segmesh::dc
