#include "segmesh/detail/surface_roles.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>

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
  tbb::enumerable_thread_specific<std::vector<EdgeSide>> found;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, s.sides.size(), size_t{1} << 13),
                    [&](const tbb::blocked_range<size_t>& r) {
                      auto& out = found.local();
                      for (size_t t = r.begin(); t != r.end(); ++t) {
                        const uint32_t* x = idx + 3 * t;
                        for (int c = 0; c < 3; ++c) {
                          const uint32_t a = x[c], b = x[(c + 1) % 3];
                          if (a != b && several[a] && several[b])
                            out.push_back(
                                {std::min(a, b), std::max(a, b), pair_key(s.sides[t], kind)});
                        }
                      }
                    });
  std::vector<EdgeSide> edges;
  for (const auto& part : found) edges.insert(edges.end(), part.begin(), part.end());
  tbb::parallel_sort(edges.begin(), edges.end(), [](const EdgeSide& p, const EdgeSide& q) {
    return p.a != q.a ? p.a < q.a : p.b != q.b ? p.b < q.b : p.key < q.key;
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
