#include "segmesh/detail/surface_roles.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>

#include "segmesh/detail/triangle_scatter.hpp"

namespace segmesh {

namespace {

uint64_t pair_key(const std::array<uint32_t, 2>& sides, InterfaceSides kind) {
  if (kind == InterfaceSides::either_way) {
    // (larger, smaller): a part against the background keeps its (part, 0) key.
    return uint64_t{std::max(sides[0], sides[1])} << 32 | std::min(sides[0], sides[1]);
  }
  return uint64_t{sides[0]} << 32 | sides[1];
}

}  // namespace

SurfaceRoles surface_roles(const LabelledSurface& s, InterfaceSides kind) {
  const size_t nv = s.mesh.positions.size();
  const uint32_t* idx = s.mesh.indices.data();
  // The first interface each vertex is met on, and whether it is on a second one (a scatter over
  // the triangles: the result does not depend on the order they are met in).
  constexpr uint64_t kNone = ~uint64_t{0};
  std::vector<uint64_t> first(nv, kNone);
  std::vector<uint8_t> several(nv, 0);
  scatter_triangles(triangle_chunks(s.mesh.indices), [&](size_t t0, size_t t1) {
    for (size_t t = t0; t < t1; ++t) {
      const uint64_t key = pair_key(s.sides[t], kind);
      for (int c = 0; c < 3; ++c) {
        const uint32_t v = idx[3 * t + size_t(c)];
        if (first[v] == kNone) {
          first[v] = key;
        } else if (first[v] != key) {
          several[v] = 1;
        }
      }
    }
  });
  // The edges between two such vertices, with the interface of each triangle along them; an
  // edge of two or more interfaces is a junction curve's.
  struct EdgeSide {
    uint32_t a, b;
    uint64_t key;
  };
  // Grouped by the lower vertex by a counting sort (on a map of random labels nearly every
  // vertex is on several interfaces, and a comparison sort of the 2.4 M edge sides took 0.3 s of
  // CPU): counted and placed in parallel passes over the triangles, in whatever order the
  // threads meet them, then each vertex's few sorted by (b, key), which makes the order exact.
  // The triangles with two corners on several interfaces (the only ones with such an edge), found
  // in one pass over all triangles, per block of triangles; the two passes below visit only them.
  constexpr size_t kBlock = size_t{1} << 13;
  const size_t blocks = (s.sides.size() + kBlock - 1) / kBlock;
  std::vector<std::vector<uint32_t>> junction_triangles(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
    for (size_t t = b * kBlock, end = std::min(s.sides.size(), (b + 1) * kBlock); t < end; ++t) {
      const uint32_t* x = idx + 3 * t;
      if (several[x[0]] + several[x[1]] + several[x[2]] >= 2)
        junction_triangles[b].push_back(uint32_t(t));
    }
  });
  auto for_each_edge = [&](auto&& visit) {
    tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
      for (const uint32_t t : junction_triangles[b]) {
        const uint32_t* x = idx + 3 * size_t{t};
        for (int c = 0; c < 3; ++c) {
          const uint32_t a = x[c], e = x[(c + 1) % 3];
          if (a != e && several[a] && several[e]) visit(std::min(a, e), std::max(a, e), t);
        }
      }
    });
  };
  std::vector<uint32_t> start(nv + 1, 0);
  for_each_edge([&](uint32_t a, uint32_t, size_t) {
    std::atomic_ref<uint32_t>(start[a + 1]).fetch_add(1, std::memory_order_relaxed);
  });
  for (size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<EdgeSide> edges(start[nv]);
  {
    std::vector<uint32_t> at(start.begin(), start.end() - 1);
    for_each_edge([&](uint32_t a, uint32_t b, size_t t) {
      const uint32_t i = std::atomic_ref<uint32_t>(at[a]).fetch_add(1, std::memory_order_relaxed);
      edges[i] = {a, b, pair_key(s.sides[t], kind)};
    });
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nv, size_t{1} << 14),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t v = r.begin(); v != r.end(); ++v)
                        std::sort(edges.begin() + start[v], edges.begin() + start[v + 1],
                                  [](const EdgeSide& p, const EdgeSide& q) {
                                    return p.b != q.b ? p.b < q.b : p.key < q.key;
                                  });
                    });
  SurfaceRoles out;
  std::vector<uint32_t> curve_degree(nv, 0);
  for (size_t i = 0; i < edges.size();) {
    size_t j = i + 1;
    bool junction = false;
    for (; j < edges.size() && edges[j].a == edges[i].a && edges[j].b == edges[i].b; ++j) {
      junction = junction || edges[j].key != edges[i].key;
    }
    if (junction) {
      out.smooth.curve_edges.push_back({edges[i].a, edges[i].b});
      ++curve_degree[edges[i].a];
      ++curve_degree[edges[i].b];
    }
    i = j;
  }
  out.smooth.role.resize(nv);
  out.free_material.assign(nv, 0);
  for (size_t v = 0; v < nv; ++v) {
    if (!several[v]) {
      out.smooth.role[v] = SmoothRole::kSheet;
      // A part's surface against the background: (part, 0), the part inside.
      if (first[v] != kNone && (first[v] & 0xffffffffu) == 0) {
        out.free_material[v] = static_cast<uint32_t>(first[v] >> 32);
      }
    } else {
      out.smooth.role[v] = curve_degree[v] == 2 ? SmoothRole::kCurve : SmoothRole::kFixed;
      out.smooth.pinned.push_back(static_cast<uint32_t>(v));
    }
  }
  return out;
}

}  // namespace segmesh
