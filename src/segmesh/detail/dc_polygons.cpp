#include "segmesh/detail/dc_polygons.hpp"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "segmesh/quality.hpp"

namespace segmesh::dc {

namespace {

bool triangulable(const Polygon& p) {
  if (p.n <= 4) return true;
  std::vector<std::array<int, 3>> unused;
  return triangulate(p, [](int, int, int) { return 1.0; }, unused);
}

inline float squared_distance(Vec3f a, Vec3f b) {
  const float x = a.x - b.x, y = a.y - b.y, z = a.z - b.z;
  return x * x + y * y + z * z;
}

// The radii ratio of a triangle with sides a, b, c, without the sorting of radii_ratio_of_sides
// (quality.hpp): only used to choose between two diagonals, where float and the plain product
// suffice; 0 for degenerate triangles.
inline float sides_ratio(float a, float b, float c) {
  const float f = (b + c - a) * (c + a - b) * (a + b - c);
  const float abc = a * b * c;
  return f > 0 && abc > 0 ? f / abc : 0.0f;
}

// Which diagonal splits the quad p0 p1 p2 p3 into the better pair of triangles (the higher worst
// sides_ratio): 0 for p0-p2, 1 for p1-p3 (only when better by more than 1e-6).
inline int better_diagonal(Vec3f p0, Vec3f p1, Vec3f p2, Vec3f p3) {
  const float s01 = std::sqrt(squared_distance(p0, p1)), s12 = std::sqrt(squared_distance(p1, p2)),
              s23 = std::sqrt(squared_distance(p2, p3)), s30 = std::sqrt(squared_distance(p3, p0)),
              l02 = std::sqrt(squared_distance(p0, p2)), l13 = std::sqrt(squared_distance(p1, p3));
  const float d02 = std::min(sides_ratio(s01, s12, l02), sides_ratio(l02, s23, s30));
  const float d13 = std::min(sides_ratio(s12, s23, l13), sides_ratio(l13, s30, s01));
  return d13 > d02 + 1e-6f ? 1 : 0;
}

inline void write_quad(const PendingQuad& q, int diagonal) {
  const uint32_t a = q.v[diagonal], b = q.v[diagonal + 1], c = q.v[diagonal + 2],
                 d = q.v[(diagonal + 3) % 4];
  q.out[0] = a, q.out[1] = b, q.out[2] = c, q.out[3] = a, q.out[4] = c, q.out[5] = d;
}

}  // namespace

Polygon polygon(const DcTable& table, int axis, const std::array<CellRef, 4>& quadrant,
                bool inside_at_start, bool mirrored) {
  Polygon p;
  for (int q = 0; q < 4; ++q) {
    const CellRef& cell = quadrant[q];
    if (cell.cs == kOneSheet) {
      p.vertex[p.n] = cell.first_vertex;
      p.quadrant[p.n++] = q;
      continue;
    }
    const DcCase& dc = table.cases[static_cast<size_t>(cell.cs)];
    const int e = local_edge(axis, -kQuadrantDu[q], -kQuadrantDv[q]);
    const int count = dc.around_count[e];
    for (int t = 0; t < count; ++t) {
      const int piece = dc.around[e][kQuadrantForward[q] ? t : count - 1 - t];
      p.vertex[p.n] = cell.first_vertex + static_cast<uint32_t>(piece);
      p.quadrant[p.n++] = q;
    }
  }
  // Counter-clockwise around +axis faces +axis: right when the inside is at the edge's start.
  // A mirrored grid flips every winding once more.
  if (inside_at_start == mirrored) {
    std::reverse(p.vertex.begin(), p.vertex.begin() + p.n);
    std::reverse(p.quadrant.begin(), p.quadrant.begin() + p.n);
  }
  return p;
}

std::pair<uint64_t, uint64_t> polygon_cost(const Polygon& p) {
  if (p.n == 4) return {2, 0};
  if (triangulable(p)) return {uint64_t(p.n - 2), 0};
  return {uint64_t(p.n), 1};
}

uint32_t* write_polygon(const Polygon& p, TriMesh& mesh, uint32_t& extra, uint32_t* out,
                        std::vector<std::array<int, 3>>& scratch) {
  const bool normals = !mesh.normals.empty();
  auto pos = [&](int a) { return to_double(mesh.positions[p.vertex[a]]); };
  auto rho = [&](int a, int b, int c) { return radii_ratio(pos(a), pos(b), pos(c)); };
  if (triangulate(p, rho, scratch)) {
    for (const auto& t : scratch) {
      out[0] = p.vertex[t[0]], out[1] = p.vertex[t[1]], out[2] = p.vertex[t[2]];
      out += 3;
    }
    return out;
  }
  // No manifold-safe diagonals: a fan around a new vertex at the polygon's centroid.
  Vec3d centre{}, normal{};
  for (int a = 0; a < p.n; ++a) {
    centre = centre + pos(a);
    if (normals) normal = normal + to_double(mesh.normals[p.vertex[a]]);
  }
  mesh.positions[extra] = to_float((1.0 / p.n) * centre);
  if (normals) {
    const double nl = norm(normal);
    mesh.normals[extra] = nl > 0 ? to_float((1.0 / nl) * normal) : Vec3f{0, 0, 1};
  }
  for (int a = 0; a < p.n; ++a) {
    out[0] = extra, out[1] = p.vertex[a], out[2] = p.vertex[(a + 1) % p.n];
    out += 3;
  }
  ++extra;
  return out;
}

void split_quads(const Vec3f* v, const PendingQuad* q, size_t n) {
  size_t i = 0;
#if defined(__SSE2__)
  for (; i + 4 <= n; i += 4) {
    __m128 x[4], y[4], z[4];
    for (int c = 0; c < 4; ++c) {
      const Vec3f &a = v[q[i].v[c]], &b = v[q[i + 1].v[c]], &e = v[q[i + 2].v[c]],
                  &f = v[q[i + 3].v[c]];
      x[c] = _mm_setr_ps(a.x, b.x, e.x, f.x);
      y[c] = _mm_setr_ps(a.y, b.y, e.y, f.y);
      z[c] = _mm_setr_ps(a.z, b.z, e.z, f.z);
    }
    auto length = [&](int s, int t) {  // as std::sqrt(squared_distance(p_s, p_t))
      const __m128 dx = _mm_sub_ps(x[s], x[t]), dy = _mm_sub_ps(y[s], y[t]),
                   dz = _mm_sub_ps(z[s], z[t]);
      return _mm_sqrt_ps(
          _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz)));
    };
    auto ratio = [](__m128 a, __m128 b, __m128 c) {  // as sides_ratio(a, b, c)
      const __m128 f =
          _mm_mul_ps(_mm_mul_ps(_mm_sub_ps(_mm_add_ps(b, c), a), _mm_sub_ps(_mm_add_ps(c, a), b)),
                     _mm_sub_ps(_mm_add_ps(a, b), c));
      const __m128 abc = _mm_mul_ps(_mm_mul_ps(a, b), c);
      const __m128 zero = _mm_setzero_ps();
      return _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(f, zero), _mm_cmpgt_ps(abc, zero)),
                        _mm_div_ps(f, abc));
    };
    const __m128 s01 = length(0, 1), s12 = length(1, 2), s23 = length(2, 3), s30 = length(3, 0),
                 l02 = length(0, 2), l13 = length(1, 3);
    // std::min(p, q) is q < p ? q : p, _mm_min_ps(q, p).
    const __m128 d02 = _mm_min_ps(ratio(l02, s23, s30), ratio(s01, s12, l02));
    const __m128 d13 = _mm_min_ps(ratio(l13, s30, s01), ratio(s12, s23, l13));
    const int choice = _mm_movemask_ps(_mm_cmpgt_ps(d13, _mm_add_ps(d02, _mm_set1_ps(1e-6f))));
    for (int k = 0; k < 4; ++k) write_quad(q[i + size_t(k)], choice >> k & 1);
  }
#endif
  for (; i < n; ++i)
    write_quad(q[i], better_diagonal(v[q[i].v[0]], v[q[i].v[1]], v[q[i].v[2]], v[q[i].v[3]]));
}

}  // namespace segmesh::dc
