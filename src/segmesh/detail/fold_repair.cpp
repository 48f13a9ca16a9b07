#include "segmesh/detail/fold_repair.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace segmesh {

namespace {

// The triangles within reach of the junctions: every corner within `reach` edges of a curve or
// fixed vertex. (Every fold measured on the phantom with Marching Cubes had a triangle with a
// junction corner; multi-label Dual Contouring on the 3 mm TotalSegmentator map folded 246 and
// 256 triangles of two contacts with one ring examined and none with two.)
std::vector<uint32_t> triangles_near_junctions(const TriMesh& mesh,
                                               const std::vector<SmoothRole>& role, int reach) {
  const size_t nt = mesh.triangle_count();
  const uint32_t* idx = mesh.indices.data();
  // Passes over fixed blocks of triangles in parallel; a corner is marked with a relaxed atomic
  // store (several triangles may mark one vertex at once, always with 1).
  constexpr size_t kBlock = size_t{1} << 14;
  const size_t blocks = (nt + kBlock - 1) / kBlock;
  auto for_each_block = [&](auto&& body) {
    tbb::parallel_for(size_t{0}, blocks, [&](size_t b) {
      body(b, b * kBlock, std::min(nt, (b + 1) * kBlock));
    });
  };
  auto mark = [](std::vector<uint8_t>& near, const uint32_t* x) {
    for (int c = 0; c < 3; ++c)
      std::atomic_ref<uint8_t>(near[x[c]]).store(1, std::memory_order_relaxed);
  };
  std::vector<uint8_t> near(role.size(), 0);
  for_each_block([&](size_t, size_t t0, size_t t1) {
    for (size_t t = t0; t < t1; ++t) {
      const uint32_t* x = idx + 3 * t;
      if (role[x[0]] != SmoothRole::kSheet || role[x[1]] != SmoothRole::kSheet ||
          role[x[2]] != SmoothRole::kSheet)
        mark(near, x);
    }
  });
  for (int ring = 1; ring < reach; ++ring) {
    std::vector<uint8_t> next = near;
    for_each_block([&](size_t, size_t t0, size_t t1) {
      for (size_t t = t0; t < t1; ++t) {
        const uint32_t* x = idx + 3 * t;
        if (near[x[0]] || near[x[1]] || near[x[2]]) mark(next, x);
      }
    });
    near.swap(next);
  }
  // The triangles with every corner near, in triangle order.
  std::vector<std::vector<uint32_t>> found(blocks);
  for_each_block([&](size_t b, size_t t0, size_t t1) {
    for (size_t t = t0; t < t1; ++t) {
      const uint32_t* x = idx + 3 * t;
      if (near[x[0]] && near[x[1]] && near[x[2]]) found[b].push_back(uint32_t(t));
    }
  });
  std::vector<uint32_t> out;
  for (const auto& block : found) out.insert(out.end(), block.begin(), block.end());
  return out;
}

// The pairs of the given triangles that cross (an edge of one through the other), each listed
// once, found with a uniform grid. With `moved` (later rounds), only pairs where a triangle has a
// moved vertex, looked for only in the cells those triangles overlap: the other pairs crossed
// before or never.
std::vector<std::array<uint32_t, 2>> crossing_pairs(const TriMesh& mesh,
                                                    const std::vector<uint32_t>& tris,
                                                    const std::vector<uint8_t>& moved) {
  const uint32_t* idx = mesh.indices.data();
  auto corner = [&](uint32_t t, int k) {
    return to_double(mesh.positions[idx[3 * t + size_t(k)]]);
  };
  // Per triangle: its box, and its corners and plane in floats for a first test of its edges
  // against another triangle (edge_through below).
  struct Box {
    Vec3d lo, hi;
  };
  struct Plane {
    float c[3][3];  // the corners
    float n[3];     // the normal, unnormalised, as segment_crosses_triangle computes it
    float margin;   // 1e-5 |n|
    float side;     // the box's largest side
  };
  std::vector<Box> box(tris.size());
  std::vector<Plane> plane(tris.size());
  std::vector<uint8_t> active(moved.empty() ? 0 : tris.size(), 0);
  Vec3d extent{}, origin{};
  for (size_t i = 0; i < tris.size(); ++i) {
    const Vec3d a = corner(tris[i], 0), b = corner(tris[i], 1), c = corner(tris[i], 2);
    const Vec3d lo{std::min({a.x, b.x, c.x}), std::min({a.y, b.y, c.y}), std::min({a.z, b.z, c.z})};
    const Vec3d hi{std::max({a.x, b.x, c.x}), std::max({a.y, b.y, c.y}), std::max({a.z, b.z, c.z})};
    box[i] = {lo, hi};
    const Vec3d n = cross(b - a, c - a), side = hi - lo;
    Plane& g = plane[i];
    for (int k = 0; k < 3; ++k) {
      const Vec3f v = mesh.positions[idx[3 * size_t(tris[i]) + size_t(k)]];
      g.c[k][0] = v.x;
      g.c[k][1] = v.y;
      g.c[k][2] = v.z;
    }
    g.n[0] = float(n.x);
    g.n[1] = float(n.y);
    g.n[2] = float(n.z);
    g.margin = float(1e-5 * norm(n));
    g.side = float(std::max({side.x, side.y, side.z}));
    extent = extent + (hi - lo);
    origin = i == 0 ? lo
                    : Vec3d{std::min(origin.x, lo.x), std::min(origin.y, lo.y),
                            std::min(origin.z, lo.z)};
    if (!moved.empty()) {
      const uint32_t* x = idx + 3 * size_t(tris[i]);
      active[i] = moved[x[0]] | moved[x[1]] | moved[x[2]];
    }
  }
  std::vector<std::array<uint32_t, 2>> pairs;
  if (tris.size() < 2) return pairs;
  // Cells twice the triangles' mean box along each axis (voxels are often anisotropic).
  const double n = double(tris.size()) / 2;
  const Vec3d cell{std::max(extent.x / n, 1e-6), std::max(extent.y / n, 1e-6),
                   std::max(extent.z / n, 1e-6)};
  auto at = [&](const Vec3d& p) {
    return std::array<uint64_t, 3>{uint64_t((p.x - origin.x) / cell.x),
                                   uint64_t((p.y - origin.y) / cell.y),
                                   uint64_t((p.z - origin.z) / cell.z)};
  };
  // 21 bits per axis: cells further apart wrap around onto one key, which only costs box tests.
  auto key = [](uint64_t x, uint64_t y, uint64_t z) {
    return (z & 0x1fffff) << 42 | (y & 0x1fffff) << 21 | (x & 0x1fffff);
  };
  // Each box's lowest cell: the lowest cell of two boxes' common part is their maximum.
  std::vector<std::array<uint64_t, 3>> low_cell(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) low_cell[i] = at(box[i].lo);
  auto for_each_cell = [&](size_t i, auto&& visit) {
    const auto& lo = low_cell[i];
    const auto hi = at(box[i].hi);
    for (uint64_t z = lo[2]; z <= hi[2]; ++z)
      for (uint64_t y = lo[1]; y <= hi[1]; ++y)
        for (uint64_t x = lo[0]; x <= hi[0]; ++x) visit(key(x, y, z));
  };
  // The cells to look in: all, or (later rounds) those the moved triangles overlap.
  std::vector<uint64_t> dirty;
  for (size_t i = 0; i < active.size(); ++i)
    if (active[i]) for_each_cell(i, [&](uint64_t k) { dirty.push_back(k); });
  std::sort(dirty.begin(), dirty.end());
  dirty.erase(std::unique(dirty.begin(), dirty.end()), dirty.end());
  // (cell key, triangle) for every cell a triangle's box overlaps.
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  for (size_t i = 0; i < tris.size(); ++i)
    for_each_cell(i, [&](uint64_t k) {
      if (moved.empty() || std::binary_search(dirty.begin(), dirty.end(), k))
        keyed.push_back({k, uint32_t(i)});
    });
  tbb::parallel_sort(keyed.begin(), keyed.end());
  // Whether an edge of triangle p other than the ones at corner `skip` (-1: none) passes through
  // triangle q: its ends first checked in floats against q's plane with a margin well above
  // their rounding (the corners are within both boxes' sides of each other, the boxes meeting),
  // so only edges that may cross it take the exact test.
  auto edge_through = [&](size_t p, size_t q, int skip) {
    const Plane& a = plane[p];
    const Plane& b = plane[q];
    float d[3];
    for (int k = 0; k < 3; ++k)
      d[k] = b.n[0] * (a.c[k][0] - b.c[0][0]) + b.n[1] * (a.c[k][1] - b.c[0][1]) +
             b.n[2] * (a.c[k][2] - b.c[0][2]);
    const float tol = b.margin * (a.side + b.side);
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      if (k == skip || l == skip) continue;
      if (std::min(d[k], d[l]) >= tol || std::max(d[k], d[l]) <= -tol) continue;
      if (segment_crosses_triangle(corner(tris[p], k), corner(tris[p], l), corner(tris[q], 0),
                                   corner(tris[q], 1), corner(tris[q], 2)))
        return true;
    }
    return false;
  };
  std::vector<size_t> cell_start;
  for (size_t c = 0; c < keyed.size(); ++c)
    if (c == 0 || keyed[c].first != keyed[c - 1].first) cell_start.push_back(c);
  cell_start.push_back(keyed.size());
  // Per cell, its triangles gathered into one compact array (float box, corners), so the pair
  // loop, most of whose pairs are a junction's fan sharing a corner, runs in cache.
  struct Entry {
    float lo[3], hi[3];
    uint32_t v[3];
    uint32_t i;
  };
  // The crossing pairs first met in one cell, added to `out`.
  auto scan_cell = [&](size_t cell, std::vector<Entry>& local,
                       std::vector<std::array<uint32_t, 2>>& out) {
    const uint64_t here = keyed[cell_start[cell]].first;
    local.clear();
    for (size_t k = cell_start[cell]; k < cell_start[cell + 1]; ++k) {
      const uint32_t i = keyed[k].second;
      const Box& b = box[i];
      const uint32_t* x = idx + 3 * size_t(tris[i]);
      local.push_back({{float(b.lo.x), float(b.lo.y), float(b.lo.z)},
                       {float(b.hi.x), float(b.hi.y), float(b.hi.z)},
                       {x[0], x[1], x[2]},
                       i});
    }
    for (size_t i = 0; i < local.size(); ++i) {
      const Entry& ep = local[i];
      for (size_t j = i + 1; j < local.size(); ++j) {
        const Entry& eq = local[j];
        if (ep.lo[0] > eq.hi[0] || eq.lo[0] > ep.hi[0] || ep.lo[1] > eq.hi[1] ||
            eq.lo[1] > ep.hi[1] || ep.lo[2] > eq.hi[2] || eq.lo[2] > ep.hi[2])
          continue;  // the boxes do not meet
        // Two triangles on one edge cannot cross strictly; two on one corner can (a fan folded
        // over itself: the edge opposite the corner through the other triangle).
        int shared = 0, skip_p = -1, skip_q = -1;
        for (int u = 0; u < 3; ++u)
          for (int w = 0; w < 3; ++w)
            if (ep.v[u] == eq.v[w]) {
              ++shared;
              skip_p = u;
              skip_q = w;
            }
        if (shared >= 2) continue;
        const uint32_t p = ep.i, q = eq.i;
        if (!moved.empty() && !active[p] && !active[q]) continue;
        // Each pair once: in the cell holding the low corner of the boxes' common part.
        const auto& lp = low_cell[p];
        const auto& lq = low_cell[q];
        if (key(std::max(lp[0], lq[0]), std::max(lp[1], lq[1]), std::max(lp[2], lq[2])) != here)
          continue;
        const uint32_t s = tris[p], t = tris[q];
        if (edge_through(p, q, skip_p) || edge_through(q, p, skip_q))
          out.push_back({std::min(s, t), std::max(s, t)});
      }
    }
  };
  tbb::enumerable_thread_specific<std::vector<std::array<uint32_t, 2>>> found;
  tbb::enumerable_thread_specific<std::vector<Entry>> gathered;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, cell_start.size() - 1, 256),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t cell = r.begin(); cell != r.end(); ++cell)
                        scan_cell(cell, gathered.local(), found.local());
                    });
  for (const auto& part : found) pairs.insert(pairs.end(), part.begin(), part.end());
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

}  // namespace

bool segment_crosses_triangle(Vec3d p, Vec3d q, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d n = cross(b - a, c - a);
  const double dp = dot(n, p - a), dq = dot(n, q - a);
  const double scale = norm(n) * (norm(q - p) + 1e-12);
  if (!(dp * dq < 0) || std::abs(dp) < 1e-6 * scale || std::abs(dq) < 1e-6 * scale) return false;
  const Vec3d x = p + (dp / (dp - dq)) * (q - p);
  const double nn = dot(n, n);
  const double u = dot(cross(c - b, x - b), n) / nn, v = dot(cross(a - c, x - c), n) / nn;
  const double w = 1 - u - v;
  return u > 1e-6 && v > 1e-6 && w > 1e-6;
}

size_t repair_folds(TriMesh& mesh, const std::vector<Vec3f>& extracted,
                    const std::vector<SmoothRole>& role, int reach) {
  const std::vector<uint32_t> tris = triangles_near_junctions(mesh, role, reach);
  const uint32_t* idx = mesh.indices.data();
  std::vector<uint8_t> moved_back(mesh.positions.size(), 0), moved_now;
  size_t count = 0;
  for (int round = 0; round <= kFoldRounds; ++round) {
    const auto pairs = crossing_pairs(mesh, tris, moved_now);
    if (pairs.empty()) break;
    // Each vertex of a crossing pair once per round: half-way back, or (last round) all the way.
    std::vector<uint32_t> verts;
    for (const auto& [s, t] : pairs)
      for (int k = 0; k < 3; ++k) {
        verts.push_back(idx[3 * s + size_t(k)]);
        verts.push_back(idx[3 * t + size_t(k)]);
      }
    std::sort(verts.begin(), verts.end());
    verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
    const float keep = round == kFoldRounds ? 0.0f : 0.5f;
    moved_now.assign(mesh.positions.size(), 0);
    for (uint32_t v : verts) {
      const Vec3f a = extracted[v], b = mesh.positions[v];
      mesh.positions[v] = {a.x + keep * (b.x - a.x), a.y + keep * (b.y - a.y),
                           a.z + keep * (b.z - a.z)};
      count += !moved_back[v];
      moved_back[v] = moved_now[v] = 1;
    }
  }
  return count;
}

}  // namespace segmesh
