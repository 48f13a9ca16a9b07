#include "segmesh/detail/fold_repair.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace segmesh {

namespace {

// The triangles within reach of the junctions: every corner a curve or fixed vertex or one of
// their neighbours. (Every fold measured on the phantom had a triangle with a junction corner.)
std::vector<uint32_t> triangles_near_junctions(const TriMesh& mesh,
                                               const std::vector<SmoothRole>& role) {
  const size_t nt = mesh.triangle_count();
  const uint32_t* idx = mesh.indices.data();
  std::vector<uint8_t> near(role.size(), 0);
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t* x = idx + 3 * t;
    if (role[x[0]] != SmoothRole::kSheet || role[x[1]] != SmoothRole::kSheet ||
        role[x[2]] != SmoothRole::kSheet)
      near[x[0]] = near[x[1]] = near[x[2]] = 1;
  }
  std::vector<uint32_t> out;
  for (size_t t = 0; t < nt; ++t) {
    const uint32_t* x = idx + 3 * t;
    if (near[x[0]] && near[x[1]] && near[x[2]]) out.push_back(uint32_t(t));
  }
  return out;
}

// The pairs of the given triangles that cross (an edge of one through the other), each listed
// once, found with a uniform grid.
std::vector<std::array<uint32_t, 2>> crossing_pairs(const TriMesh& mesh,
                                                    const std::vector<uint32_t>& tris,
                                                    const std::vector<uint8_t>& moved) {
  const uint32_t* idx = mesh.indices.data();
  auto corner = [&](uint32_t t, int k) { return to_double(mesh.positions[idx[3 * t + size_t(k)]]); };
  std::vector<std::array<Vec3d, 2>> box(tris.size());
  Vec3d extent{}, origin{};
  for (size_t i = 0; i < tris.size(); ++i) {
    Vec3d lo = corner(tris[i], 0), hi = lo;
    for (int k = 1; k < 3; ++k) {
      const Vec3d v = corner(tris[i], k);
      lo = {std::min(lo.x, v.x), std::min(lo.y, v.y), std::min(lo.z, v.z)};
      hi = {std::max(hi.x, v.x), std::max(hi.y, v.y), std::max(hi.z, v.z)};
    }
    box[i] = {lo, hi};
    extent = extent + (hi - lo);
    origin = i == 0 ? lo
                    : Vec3d{std::min(origin.x, lo.x), std::min(origin.y, lo.y),
                            std::min(origin.z, lo.z)};
  }
  std::vector<std::array<uint32_t, 2>> pairs;
  if (tris.size() < 2) return pairs;
  // Cells as large as the triangles' mean box along each axis (voxels are often anisotropic).
  const double n = double(tris.size()) / 3;
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
  // (cell key, triangle) for every cell a triangle's box overlaps.
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  for (size_t i = 0; i < tris.size(); ++i) {
    const auto lo = at(box[i][0]), hi = at(box[i][1]);
    for (uint64_t z = lo[2]; z <= hi[2]; ++z)
      for (uint64_t y = lo[1]; y <= hi[1]; ++y)
        for (uint64_t x = lo[0]; x <= hi[0]; ++x) keyed.push_back({key(x, y, z), uint32_t(i)});
  }
  std::sort(keyed.begin(), keyed.end());
  auto shares_vertex = [&](uint32_t s, uint32_t t) {
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (idx[3 * s + size_t(a)] == idx[3 * t + size_t(b)]) return true;
    return false;
  };
  auto edge_through = [&](uint32_t s, uint32_t t) {
    for (int k = 0; k < 3; ++k)
      if (segment_crosses_triangle(corner(s, k), corner(s, (k + 1) % 3), corner(t, 0), corner(t, 1),
                                   corner(t, 2)))
        return true;
    return false;
  };
  // With `moved`, only pairs where a triangle has a moved vertex: the others crossed before or
  // never.
  std::vector<uint8_t> active(moved.empty() ? 0 : tris.size(), 0);
  for (size_t i = 0; i < active.size(); ++i) {
    const uint32_t* x = idx + 3 * size_t(tris[i]);
    active[i] = moved[x[0]] | moved[x[1]] | moved[x[2]];
  }
  std::vector<size_t> cell_start;
  for (size_t c = 0; c < keyed.size(); ++c)
    if (c == 0 || keyed[c].first != keyed[c - 1].first) cell_start.push_back(c);
  cell_start.push_back(keyed.size());
  tbb::enumerable_thread_specific<std::vector<std::array<uint32_t, 2>>> found;
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, cell_start.size() - 1, 256),
      [&](const tbb::blocked_range<size_t>& r) {
        auto& out = found.local();
        for (size_t cell = r.begin(); cell != r.end(); ++cell) {
          const size_t c = cell_start[cell], e = cell_start[cell + 1];
          for (size_t i = c; i < e; ++i)
            for (size_t j = i + 1; j < e; ++j) {
              const size_t p = keyed[i].second, q = keyed[j].second;
              if (!moved.empty() && !active[p] && !active[q]) continue;
              const auto& [a0, a1] = box[p];
              const auto& [b0, b1] = box[q];
              const Vec3d lo{std::max(a0.x, b0.x), std::max(a0.y, b0.y), std::max(a0.z, b0.z)};
              if (lo.x > std::min(a1.x, b1.x) || lo.y > std::min(a1.y, b1.y) ||
                  lo.z > std::min(a1.z, b1.z))
                continue;  // the boxes do not meet
              // Each pair once: in the cell holding the low corner of the boxes' common part.
              const auto home = at(lo);
              if (key(home[0], home[1], home[2]) != keyed[c].first) continue;
              const uint32_t s = tris[p], t = tris[q];
              if (shares_vertex(s, t)) continue;
              if (edge_through(s, t) || edge_through(t, s))
                out.push_back({std::min(s, t), std::max(s, t)});
            }
        }
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
                    const std::vector<SmoothRole>& role) {
  const std::vector<uint32_t> tris = triangles_near_junctions(mesh, role);
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
