#include "segmesh/dual_contouring.hpp"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "segmesh/component_field.hpp"
#include "segmesh/detail/dual_contouring_simplify.hpp"
#include "segmesh/detail/dual_contouring_table.hpp"
#include "segmesh/detail/edge_intersection.hpp"
#include "segmesh/error.hpp"
#include "segmesh/first_touch.hpp"
#include "segmesh/detail/inside_bits.hpp"
#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/detail/qef.hpp"
#include "segmesh/quality.hpp"

namespace segmesh {

namespace {

// The four cells around an edge along axis a, counter-clockwise seen from +a: their offsets along
// u = (a + 1) % 3 and v = (a + 2) % 3 from the edge's grid point, and whether the cell's pieces
// around the edge run from its u-face to its v-face (entering by the u-face) or the reverse.
constexpr int kQuadrantDu[4] = {0, 0, -1, -1};
constexpr int kQuadrantDv[4] = {-1, 0, 0, -1};
constexpr bool kQuadrantForward[4] = {true, false, true, false};

// The cell edge (marching_cubes_table.hpp numbering) along `axis` at cell coordinates (cu, cv)
// along u and v.
int local_edge(int axis, int cu, int cv) {
  return axis * 4 + (axis == 1 ? cv + 2 * cu : cu + 2 * cv);
}

constexpr int kMaxPolygon = 12;



// The first n entries are set (the rest stays uninitialised: one is made per cut edge).
struct Polygon {
  int n = 0;
  std::array<uint32_t, kMaxPolygon> vertex;
  std::array<int, kMaxPolygon> quadrant;
};

// Polygon diagonals may only join sheets of the two cells that share nothing but the edge: any
// other pair may already be joined by an edge of the mesh, and a second one would be non-manifold.
bool diagonal_allowed(const Polygon& p, int i, int j) {
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

// A quad whose two triangles are written once its diagonal is chosen.
struct PendingQuad {
  uint32_t* out;   // six indices
  uint32_t v[4];   // its vertices in polygon() order
};

inline void write_quad(const PendingQuad& q, int diagonal) {
  const uint32_t a = q.v[diagonal], b = q.v[diagonal + 1], c = q.v[diagonal + 2],
                 d = q.v[(diagonal + 3) % 4];
  q.out[0] = a, q.out[1] = b, q.out[2] = c, q.out[3] = a, q.out[4] = c, q.out[5] = d;
}

// Splits each quad along better_diagonal's choice. With SSE2 four quads at a time, one per lane:
// the same IEEE operations on the same operands in the same order, so the same choice, but the
// six square roots and four quotients of four quads take six and four instructions (the choice
// was a fifth of Dual Contouring's time, one quad after the other).
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

// The Hermite data of a cell's cut edges, relative to the cell: crossing in millimetres from the
// cell's first corner (before the grid's rotation), unit outward normal in the same frame.
struct CellHermite {
  std::array<Vec3d, 12> point;
  std::array<Vec3d, 12> normal;
};

// The sheet vertices of one cell, relative to it: index-space offset from the cell's first corner
// and the sum of the crossings' unit normals in the cell's frame (world_normal turns it into the
// vertex normal), per piece. What a binary cell's neighbourhood decides completely.
struct CellVertices {
  std::array<Vec3d, kDcMaxPieces> offset;
  std::array<Vec3d, kDcMaxPieces> normal_sum;  // the crossings' unit normals added (world_normal)
};

// The sheet vertices of a cell with at most two sheets, as SolvedNeighbourhoods keeps them (plain
// arrays: nothing to initialise for the cells that only read them): world offset from the cell's
// first corner (grid rotation and spacing applied, so a cell's vertex is its corner plus this).
// The offsets are float: a rounding of 1e-7 of the cell's size, far below the float positions'
// own, and half the bytes every cell's lookup reads (pelvis 12.1 to 11.3 ms at one thread).
struct SheetVertices {
  static constexpr int kPieces = 2;
  float offset[kPieces][3];
};
// Their world unit normals, kept apart: only read when vertex normals are asked for (without
// them in the table, the pelvis's tables are half the fresh memory).
struct SheetNormals {
  float normal[SheetVertices::kPieces][3];
};

// A table from neighbourhood keys (Extractor::neighbourhood) to values, for one thread: open
// addressing on the key (linear probing, at most half full, grown by rehashing the keys), the
// values in the order they were made. Keys are never 0 (no non-trivial cell has an empty
// neighbourhood).
template <class Value>
class KeyTable {
 public:
  // The index of the entry for `key` (in the order the entries were made), made by make(Value&)
  // when missing.
  template <class Make>
  uint32_t get(uint64_t key, Make&& make) {
    size_t h = hash(key) & mask_;
    for (; keys_[h] != 0; h = (h + 1) & mask_) {
      if (keys_[h] == key) return index_[h];
    }
    return add(h, key, make);
  }
  const Value& operator[](uint32_t index) const { return values_[index]; }

 private:
  // The new entry for `key` at free slot h (not inlined: get's loop stays small).
  template <class Make>
  __attribute__((noinline)) uint32_t add(size_t h, uint64_t key, Make& make) {
    Value v;
    make(v);
    const auto index = static_cast<uint32_t>(values_.size());
    keys_[h] = key;
    index_[h] = index;
    values_.push_back(v);
    if (2 * values_.size() > keys_.size()) grow();
    return index;
  }

  static size_t hash(uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return static_cast<size_t>(k);
  }
  void grow() {
    std::vector<uint64_t> keys(2 * keys_.size(), 0);
    std::vector<uint32_t> index(keys.size());
    const size_t mask = keys.size() - 1;
    for (size_t i = 0; i < keys_.size(); ++i) {
      if (keys_[i] == 0) continue;
      size_t h = hash(keys_[i]) & mask;
      while (keys[h] != 0) h = (h + 1) & mask;
      keys[h] = keys_[i];
      index[h] = index_[i];
    }
    keys_.swap(keys);
    index_.swap(index);
    mask_ = mask;
    values_.reserve(keys_.size() / 2);
  }

  // values_ has room for as many entries as the slots take (half of them), so it never moves
  // before the table grows, and its pages are first touched as entries come (growing it entry by
  // entry copied it a dozen times, each time onto fresh pages).
  static constexpr size_t kInitialSlots = 16384;
  std::vector<uint64_t> keys_ = std::vector<uint64_t>(kInitialSlots, 0);  // 0: empty slot
  std::vector<uint32_t> index_ = std::vector<uint32_t>(kInitialSlots);    // into values_
  std::vector<Value> values_ = reserved(kInitialSlots / 2);
  size_t mask_ = kInitialSlots - 1;
  static std::vector<Value> reserved(size_t n) {
    std::vector<Value> v;
    v.reserve(n);
    return v;
  }
};

// The bit of point (x, y, z) (each 0 .. 3, the cell's corners at 1 and 2) in a neighbourhood key
// (Extractor::neighbourhood): bit n + 16 x, n = y + 4 z.
constexpr uint64_t key_bit(int x, int y, int z) {
  return uint64_t{1} << (y + 4 * z + 16 * x);
}
// Whether that point is inside.
inline bool key_point(uint64_t key, int x, int y, int z) {
  return (key & key_bit(x, y, z)) != 0;
}

// The neighbourhood key (Extractor::neighbourhood: bit n + 16 x for point (x, y, z),
// n = y + 4 z) of the 4 x 4 x 4 points mirrored about the cell's centre along the axes set in
// `axes` (bit a for axis a): coordinate c becomes 3 - c.
inline uint64_t mirror_key(uint64_t k, int axes) {
  if (axes & 1) {  // x: the four 16-bit columns in reverse order
    k = (k >> 32) | (k << 32);
    k = ((k >> 16) & 0x0000ffff0000ffffULL) | ((k & 0x0000ffff0000ffffULL) << 16);
  }
  if (axes & 2) {  // y: the four bits of every nibble in reverse order
    k = ((k >> 1) & 0x5555555555555555ULL) | ((k & 0x5555555555555555ULL) << 1);
    k = ((k >> 2) & 0x3333333333333333ULL) | ((k & 0x3333333333333333ULL) << 2);
  }
  if (axes & 4) {  // z: the four nibbles of every column in reverse order
    k = ((k >> 4) & 0x0f0f0f0f0f0f0f0fULL) | ((k & 0x0f0f0f0f0f0f0f0fULL) << 4);
    k = ((k >> 8) & 0x00ff00ff00ff00ffULL) | ((k & 0x00ff00ff00ff00ffULL) << 8);
  }
  return k;
}

// The smallest of a key's eight mirror images, and the mirror that gives it (the lowest such).
struct CanonicalKey {
  uint64_t key;
  int axes;
};
inline CanonicalKey canonical_key(uint64_t k) {
  CanonicalKey best{k, 0};
  for (int axes = 1; axes < 8; ++axes) {
    const uint64_t m = mirror_key(k, axes);
    if (m < best.key) best = {m, axes};
  }
  return best;
}

// A single sheet solved in its canonical neighbourhood's frame: index-space offset from the cell's
// first corner, and the sum of its crossings' unit normals before the grid's rotation.
struct CanonicalSheet {
  double offset[3];
  double normal_sum[3];
};

// One thread's solved neighbourhoods. The QEF of a cell of a 0/1 field is a function of its
// neighbourhood alone, and a surface has few distinct neighbourhoods (8 800 among the 2.6 million
// cells of make_big.py's bones with central differences, 6 200 among the phantom's 450 000,
// 9 800 among the pelvis's 108 000), fewer still up to mirror images (2 100, 1 400 and 3 900):
// the QEF, its solution and the cell's box all mirror with the cell (spacing and margins do not
// change), so a single-sheet cell is solved once per mirror class, in the frame of the class's
// smallest key, and mirrored back. `by_key` holds every key met (its vertices in its own frame,
// world normals); `by_class` the solved classes. Cells with two sheets are solved under their own
// key (which sheet is which would need mirroring too; they are rare). Kept by DcNeighbourhoods
// across the parts of a scene; only its own thread uses it, so nothing is locked, and a
// neighbourhood met by two threads is solved by both, with the same result: the output does not
// depend on the threads. (A table shared by the threads, filled by compare-and-swap, with a small
// direct-mapped copy per thread in front of it, was built anew for every part: on the phantom it
// cost more in page faults and cache misses than the solves it shared saved.)
struct SolvedNeighbourhoods {
  KeyTable<SheetVertices> by_key;
  std::vector<SheetNormals> normals;  // by_key's entries' normals, in its order (when asked for)
  KeyTable<CanonicalSheet> by_class;
};

}  // namespace

struct DcNeighbourhoods::Tables {
  // What the entries are solved for: the cell's shape and rotation and the options that shape a
  // QEF vertex, and whether they keep vertex normals.
  std::array<double, 3> spacing;
  Mat3d direction;
  int connectivity;
  NormalMethod normals;
  double svd_eps;
  bool vertex_normals;
  tbb::enumerable_thread_specific<SolvedNeighbourhoods> threads;  // made on first use per thread

  bool fits(const Grid& g, const DcOptions& o) const {
    return g.spacing == spacing && g.direction == direction && o.connectivity == connectivity &&
           o.normals == normals && o.svd_eps == svd_eps && o.vertex_normals == vertex_normals;
  }
};

namespace {

// A cell around a cut edge as polygon() needs it: its first sheet vertex and its case, or
// kOneSheet for a cell known to hold a single sheet (whose vertex is then its first).
constexpr int kOneSheet = -1;
struct CellRef {
  int cs = kOneSheet;
  uint32_t first_vertex = 0;
};

// The points of a neighbourhood (key bits, Extractor::neighbourhood) its cell's vertices depend
// on, per case, for central differences ([0]) and Sobel ([1]): the cell's corners, and what the
// gradient reads around each corner with a cut edge (the gradients of the others are never used).
// Keys that differ elsewhere have the same solution, so their classes are one: 17 % fewer solves
// on the pelvis, 12 % on the phantom. (Applied to every cell's key, this would also make fewer
// keys, 12 % on the pelvis, but the per-cell mask cost the phantom more than the pelvis gained.)
constexpr std::array<std::array<uint64_t, 256>, 2> kRelevantPoints = [] {
  std::array<std::array<uint64_t, 256>, 2> out{};
  for (int sobel = 0; sobel < 2; ++sobel) {
    for (int cs = 0; cs < 256; ++cs) {
      uint64_t& mask = out[size_t(sobel)][size_t(cs)];
      for (int n = 0; n < 8; ++n) {
        const int x = 1 + (n & 1), y = 1 + (n >> 1 & 1), z = 1 + (n >> 2);
        mask |= key_bit(x, y, z);
        const int inside = cs >> n & 1;
        if ((cs >> (n ^ 1) & 1) == inside && (cs >> (n ^ 2) & 1) == inside &&
            (cs >> (n ^ 4) & 1) == inside) {
          continue;  // no cut edge at corner n
        }
        for (int d = 0; d < 27; ++d) {
          const int dx = d % 3 - 1, dy = d / 3 % 3 - 1, dz = d / 9 - 1;
          // Central differences read the six face neighbours, Sobel the whole 3 x 3 x 3.
          if (!sobel && dx * dx + dy * dy + dz * dz != 1) continue;
          mask |= key_bit(x + dx, y + dy, z + dz);
        }
      }
    }
  }
  return out;
}();

// One word of a row of cells: the non-trivial cells among 64 consecutive ones, and the rare ones
// among those (not exactly one sheet, or several sheets around one edge): only next to a rare
// cell can a polygon have more than four vertices, and only after one in its row are the cells
// numbered past extra sheets.
struct CellWord {
  uint64_t cells = 0;
  uint64_t rare = 0;
};

// The eight corner words of one word of cells between rows a = (j, k), b = (j + 1, k),
// c = (j, k + 1), d = (j + 1, k + 1) of inside bits: bit x of v[2 r] is the left corner of cell x
// on row r, bit x of v[2 r + 1] its right corner; so the Marching Cubes case of cell x takes bit x
// of v[n] as its corner n (marching_cubes_table.hpp numbering).
struct CornerWords {
  uint64_t v[8];
  CornerWords() = default;
  CornerWords(const uint64_t* a, const uint64_t* b, const uint64_t* c, const uint64_t* d,
              int64_t w) {
    const uint64_t* rows[4] = {a, b, c, d};
    for (int r = 0; r < 4; ++r) {
      v[2 * r] = rows[r][w];
      v[2 * r + 1] = shifted_word(rows[r], w);
    }
  }
  // The cells whose corners are not all inside or all outside.
  uint64_t nontrivial() const {
    uint64_t any = 0, all = ~uint64_t{0};
    for (uint64_t x : v) any |= x, all &= x;
    return any & ~all;
  }
  // Every cell of the word in case cs.
  static CornerWords of_case(int cs) {
    CornerWords c;
    for (int n = 0; n < 8; ++n) c.v[n] = (cs >> n & 1) ? ~uint64_t{0} : 0;
    return c;
  }
  int case_of(int b) const {
    int cs = 0;
    for (int n = 0; n < 8; ++n) cs |= int(v[n] >> b & 1) << n;
    return cs;
  }
  // The cells that may hold other than one sheet: an ambiguous face (its diagonal corners equal,
  // adjacent ones not), or two body-opposite corners that differ from the other six. The
  // Extractor checks once that every rare case of its table is among these.
  uint64_t maybe_rare() const {
    static constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                         {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    uint64_t maybe = 0;
    for (const auto& f : kFaces)
      maybe |= ~(v[f[0]] ^ v[f[2]]) & ~(v[f[1]] ^ v[f[3]]) & (v[f[0]] ^ v[f[1]]);
    for (int p = 0; p < 4; ++p) {  // corners p and 7 - p
      const int o = p == 0 ? 1 : 0;  // one of the other six
      uint64_t alone = ~(v[p] ^ v[7 - p]) & (v[p] ^ v[o]);
      for (int n = 0; n < 8; ++n) {
        if (n != p && n != 7 - p) alone &= ~(v[n] ^ v[o]);
      }
      maybe |= alone;
    }
    return maybe;
  }
  // The edges every cell owns (its edges 3, 7 and 11, at its corner 7): cut when corner 7
  // differs from corner 6, 5 or 3.
  uint64_t cut3() const { return v[6] ^ v[7]; }
  uint64_t cut7() const { return v[5] ^ v[7]; }
  uint64_t cut11() const { return v[3] ^ v[7]; }
};

// Dual Contouring on a field's inside bits (inside_bits.hpp), in the manner of marching_cubes.cpp.
// Cells live in rows (j, k), index k * cy + j, and within a row in words of 64 cells. Vertex ids
// follow the rows, the cells of a row in x order and the sheets of a cell in order; every cut
// edge's polygon is emitted by the cell that has the edge as its edge 3, 7 or 11 (the cell at the
// edge's lower corner on the two other axes), so the triangles follow the rows too. Passes, each
// parallel over rows, prefix sums between them, the output the same for any thread count:
//   1. per word of cells, the non-trivial and the rare cells; per row, the sheets;
//   2. per row, the triangles and centroid vertices of the polygons it owns: two per cut edge
//      (a quad), except next to a rare cell, where the polygon is built and priced;
//   3. the sheet vertices (QEF);
//   4. the polygons. A cell's first vertex is its row's first plus the sheets before it, a popcount
//      within its word (plus the extra sheets of rare cells before it), so no list of cells is
//      ever stored.
// `field` is the field itself, or nullptr for a component's bits (its cells are then all at least
// two grid points from the border, and their Hermite data come from their neighbourhood's bits).
template <class T>
class Extractor {
 public:
  Extractor(const Volume<T>* field, const InsideBits& bits, const Grid& grid, bool binary,
            const DcOptions& options, Progress& progress, DcNeighbourhoods* solved = nullptr)
      : f_(field),
        bits_(bits),
        grid_(grid),
        binary_(binary && options.tolerance_mm == 0),
        normals_(options.vertex_normals || options.tolerance_mm > 0),
        o_(options),
        table_(dc_table(options.connectivity)),
        progress_(progress),
        solved_(solved),
        nx_(bits.dims[0]),
        ny_(bits.dims[1]),
        nz_(bits.dims[2]),
        cx_(nx_ - 1),
        cy_(ny_ - 1),
        cz_(nz_ - 1),
        cw_((cx_ + 63) / 64),
        mirrored_(grid.mirrored()),
        relevant_points_(kRelevantPoints[options.normals == NormalMethod::sobel]),
        key_mask_(std::reduce(relevant_points_.begin(), relevant_points_.end(), uint64_t{0},
                              std::bit_or<>())) {
    for (int cs = 0; cs < 256; ++cs) {
      const DcCase& dc = table_.cases[static_cast<size_t>(cs)];
      bool rare = dc.piece_count != 1;
      for (int e = 0; e < 12; ++e) rare = rare || dc.around_count[e] > 1;
      rare_[static_cast<size_t>(cs)] = rare;
      if (rare && cs != 0 && cs != 255 && (CornerWords::of_case(cs).maybe_rare() & 1) == 0) {
        throw std::logic_error("dual contouring: a rare case the word test misses");
      }
    }
  }

  TriMesh run() {
    TriMesh mesh;
    if (nx_ < 2 || ny_ < 2 || nz_ < 2) return mesh;
    count_cells();
    count_polygons();
    prefix_sums();
    const uint64_t sheets = vertex_first_.back();
    const uint64_t vertices = sheets + extra_first_.back();
    resize_zeroed(mesh.positions, vertices);
    if (normals_) resize_zeroed(mesh.normals, vertices);
    resize_zeroed(mesh.indices, 3 * size_t{triangle_first_.back()});
    if (o_.tolerance_mm > 0) qefs_.resize(sheets);
    emit_vertices(mesh);
    emit_polygons(mesh);
    if (o_.tolerance_mm > 0) {
      DcCells cells{{cx_, cy_, cz_}, surface_cells(), &qefs_,
                    [this](int64_t i, int64_t j, int64_t k) { return bits_.at(i, j, k); }};
      mesh = simplify_dual_contour(std::move(mesh), cells, grid_, o_);
    }
    return mesh;
  }

 private:
  int64_t rows() const { return cy_ * cz_; }
  size_t row_index(int64_t j, int64_t k) const { return static_cast<size_t>(k * cy_ + j); }
  const CellWord* words(int64_t j, int64_t k) const {
    return words_.data() + row_index(j, k) * size_t(cw_);
  }
  // The four rows of inside bits at the corners of row (j, k)'s cells, word by word.
  struct CornerRows {
    const uint64_t* row[4];
    CornerWords at(int64_t w) const { return {row[0], row[1], row[2], row[3], w}; }
  };
  CornerRows corners(int64_t j, int64_t k) const {
    return {{bits_.row(j, k), bits_.row(j + 1, k), bits_.row(j, k + 1), bits_.row(j + 1, k + 1)}};
  }
  // The cells of word w that exist (x < cx).
  uint64_t valid(int64_t w) const {
    const int64_t n = cx_ - 64 * w;
    return n >= 64 ? ~uint64_t{0} : (uint64_t{1} << n) - 1;
  }
  int case_at(int64_t x, int64_t j, int64_t k) const {
    return int(bit_pair(bits_.row(j, k), x) | bit_pair(bits_.row(j + 1, k), x) << 2 |
               bit_pair(bits_.row(j, k + 1), x) << 4 | bit_pair(bits_.row(j + 1, k + 1), x) << 6);
  }
  int pieces(int cs) const { return table_.cases[static_cast<size_t>(cs)].piece_count; }

  // Pass 1, in parallel over rows: the cell words, each row's sheets (into vertex_first_[r + 1]),
  // two triangles per cut edge it owns (into triangle_first_[r + 1], corrected by
  // count_polygons), whether it has rare cells, and whether it owns a cut edge without its four
  // cells (at the row's or the grid's end). The counts become first ids in prefix_sums.
  void count_cells() {
    const size_t n = static_cast<size_t>(rows());
    resize_zeroed(words_, n * size_t(cw_));
    word_first_.reset(new uint32_t[n * size_t(cw_)]);  // set where cells are
    row_rare_.assign(n, 0);
    row_short_.assign(n, 0);
    vertex_first_.assign(n + 1, 0);
    triangle_first_.assign(n + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 64), [&](const auto& range) {
      throw_if_cancelled(progress_);
      for (int64_t r = range.begin(); r < range.end(); ++r) count_row(r % cy_, r / cy_);
    });
  }
  // Pass 1 for row (j, k).
  void count_row(int64_t j, int64_t k) {
    CellWord* out = words_.data() + row_index(j, k) * size_t(cw_);
    uint32_t* first = word_first_.get() + row_index(j, k) * size_t(cw_);
    const CornerRows rows = corners(j, k);
    uint64_t rare_any = 0, sheets = 0, triangles = 0;
    bool short_row = j + 1 >= cy_ || k + 1 >= cz_;
    for (int64_t w = 0; w < cw_; ++w) {
      const CornerWords c = rows.at(w);
      CellWord cw{c.nontrivial() & valid(w), 0};
      if (cw.cells == 0) continue;  // most words (words_ starts zeroed): no rare test
      first[w] = static_cast<uint32_t>(sheets);
      sheets += uint64_t(std::popcount(cw.cells));
      const uint64_t e7 = c.cut7() & cw.cells, e11 = c.cut11() & cw.cells;
      triangles +=
          2 * uint64_t(std::popcount(c.cut3() & cw.cells) + std::popcount(e7) + std::popcount(e11));
      // Edges 7 and 11 of the row's last cell need cells past the row's end.
      if (w == cw_ - 1 && (e7 | e11) >> ((cx_ - 1) & 63) & 1) short_row = true;
      for (uint64_t m = cw.cells & c.maybe_rare(); m != 0; m &= m - 1) {
        const int b = std::countr_zero(m);
        const int cs = c.case_of(b);
        if (rare_[static_cast<size_t>(cs)]) {
          cw.rare |= uint64_t{1} << b;
          sheets += uint64_t(pieces(cs)) - 1;
        }
      }
      rare_any |= cw.rare;
      out[w] = cw;
    }
    vertex_first_[row_index(j, k) + 1] = count32(sheets);
    triangle_first_[row_index(j, k) + 1] = count32(triangles);
    row_rare_[row_index(j, k)] = rare_any != 0;
    row_short_[row_index(j, k)] = short_row && triangles > 0;
  }

  // The sheets of the cells of row (j, k)'s word w in `mask`.
  uint32_t sheets_in(int64_t j, int64_t k, int64_t w, uint64_t mask) const {
    const CellWord& cw = words(j, k)[w];
    uint32_t n = static_cast<uint32_t>(std::popcount(cw.cells & mask));
    for (uint64_t m = cw.rare & mask; m != 0; m &= m - 1) {
      n += static_cast<uint32_t>(pieces(case_at(64 * w + std::countr_zero(m), j, k))) - 1;
    }
    return n;
  }

  // The four rows of cells around the edges row (j, k) owns — (j, k), (j + 1, k), (j, k + 1),
  // (j + 1, k + 1), as quadrant rows 0 .. 3 — seen at one word: the cells' words and the first
  // vertex of each row's word.
  struct RowQuad {
    int64_t j, k;
    bool exists[4];
    uint32_t row_first[4];  // first vertex of each row
    uint32_t first[4];      // first vertex of word w of each row (when it or word w + 1 has cells)
    CellWord word[4], next[4];  // words w and w + 1 (zero where absent)
  };

  RowQuad row_quad(int64_t j, int64_t k) const {
    RowQuad q{j, k, {}, {}, {}, {}, {}};
    for (int r = 0; r < 4; ++r) {
      const int64_t jr = j + (r & 1), kr = k + (r >> 1);
      q.exists[r] = jr < cy_ && kr < cz_;
      q.row_first[r] = q.exists[r] ? vertex_first_[row_index(jr, kr)] : 0;
    }
    return q;
  }
  void load_words(RowQuad& q, int64_t w) const {
    for (int r = 0; r < 4; ++r) {
      if (!q.exists[r]) continue;
      const size_t at = row_index(q.j + (r & 1), q.k + (r >> 1)) * size_t(cw_) + size_t(w);
      q.word[r] = words_[at];
      q.next[r] = w + 1 < cw_ ? words_[at + 1] : CellWord{};
      // An empty word's first vertex is the next word's (word_first_ is set only for words with
      // cells).
      q.first[r] = q.row_first[r] + (q.word[r].cells   ? word_first_[at]
                                     : q.next[r].cells ? word_first_[at + 1]
                                                       : 0);
    }
  }

  // Cell b (0 .. 64: 64 is bit 0 of the next word) of word w of quadrant row r, as polygon()
  // needs it; throws when absent (a cut edge without its four cells: the field is not padded).
  CellRef cell(const RowQuad& q, int r, int64_t w, int b) const {
    const int64_t jr = q.j + (r & 1), kr = q.k + (r >> 1);
    const bool present = q.exists[r] && (b < 64 ? q.word[r].cells >> b & 1 : q.next[r].cells & 1);
    if (!present) {
      throw std::logic_error(
          "dual contouring: the field is inside at its border (a cut edge without its four "
          "cells); pad it with a layer of background");
    }
    CellRef c = q.word[r].rare & below(b)
                    ? CellRef{kOneSheet, q.first[r] + sheets_in(jr, kr, w, below(b))}
                    : single_sheet(q, r, b);
    if (b < 64 ? q.word[r].rare >> b & 1 : q.next[r].rare & 1) c.cs = case_at(64 * w + b, jr, kr);
    return c;
  }
  // The cells before cell b (0 .. 64) of a word.
  static uint64_t below(int b) { return b < 64 ? (uint64_t{1} << b) - 1 : ~uint64_t{0}; }
  // Cell b of quadrant row r's word when no rare cell precedes it there and it is not rare: its
  // first vertex is a popcount.
  static CellRef single_sheet(const RowQuad& q, int r, int b) {
    return {kOneSheet,
            q.first[r] + static_cast<uint32_t>(std::popcount(q.word[r].cells & below(b)))};
  }

  // Calls visit(axis, quadrant cells, inside at the edge's start) for every cut edge row (j, k)
  // owns, in the order of the cells (x ascending) and, per cell, of its edges 3, 7 and 11. The
  // quadrant cells are the four cells around the edge in polygon() order (kQuadrantDu /
  // kQuadrantDv): their CellRefs, or with Edges::all, where no rare cell is near, their vertices
  // (std::array<uint32_t, 4>: each holds one sheet). Which edges: every one, only those next to a
  // rare cell, or every one with each of its four cells checked to exist (throws
  // std::logic_error at the first that does not: the field is not padded). Unchecked, the cells
  // of a row without rare cells are numbered by popcounts, which count_polygons has checked for
  // the rows that need it.
  enum class Edges { all, next_to_rare, all_checked };
  template <Edges which, class Visit>
  void owned_edges(int64_t j, int64_t k, Visit&& visit) const {
    const bool rare_only = which == Edges::next_to_rare;
    RowQuad q = row_quad(j, k);
    const CellWord* own = words(j, k);
    const CornerRows rows = corners(j, k);
    for (int64_t w = 0; w < cw_; ++w) {
      const uint64_t cells = own[w].cells;
      if (cells == 0) continue;
      load_words(q, w);
      const CornerWords c = rows.at(w);
      uint64_t e3 = c.cut3() & cells, e7 = c.cut7() & cells, e11 = c.cut11() & cells;
      if (rare_only) {
        auto right = [&](int r) { return (q.word[r].rare >> 1) | (q.next[r].rare << 63); };
        const uint64_t r0 = q.word[0].rare, r1 = q.word[1].rare, r2 = q.word[2].rare,
                       r3 = q.word[3].rare;
        e3 &= r0 | r1 | r2 | r3;
        e7 &= r0 | r2 | right(0) | right(2);
        e11 &= r0 | r1 | right(0) | right(1);
      }
      uint64_t rare = 0;
      for (int r = 0; r < 4; ++r) rare |= q.word[r].rare | (q.next[r].rare & 1);
      if constexpr (which == Edges::all) {
        if (rare == 0) {
          // No rare cell: every cell around the edges holds one sheet, numbered by a popcount
          // (count_polygons has checked that all four exist).
          auto id = [&](int r, int b) { return single_sheet(q, r, b).first_vertex; };
          using Ids = std::array<uint32_t, 4>;
          for (uint64_t m = e3 | e7 | e11; m != 0; m &= m - 1) {
            const int b = std::countr_zero(m);
            const uint64_t bit = uint64_t{1} << b;
            const uint32_t c0 = id(0, b);
            if (e3 & bit) visit(0, Ids{id(1, b), id(3, b), id(2, b), c0}, (c.v[6] & bit) != 0);
            if (e7 & bit) {
              visit(1, Ids{id(2, b), id(2, b + 1), id(0, b + 1), c0}, (c.v[5] & bit) != 0);
            }
            if (e11 & bit) {
              visit(2, Ids{id(0, b + 1), id(1, b + 1), id(1, b), c0}, (c.v[3] & bit) != 0);
            }
          }
          continue;
        }
      }
      for (uint64_t m = e3 | e7 | e11; m != 0; m &= m - 1) {
        const int b = std::countr_zero(m);
        const uint64_t bit = uint64_t{1} << b;
        if (e3 & bit) {
          visit(0,
                std::array<CellRef, 4>{cell(q, 1, w, b), cell(q, 3, w, b), cell(q, 2, w, b),
                                       cell(q, 0, w, b)},
                (c.v[6] & bit) != 0);
        }
        if (e7 & bit) {
          visit(1,
                std::array<CellRef, 4>{cell(q, 2, w, b), cell(q, 2, w, b + 1), cell(q, 0, w, b + 1),
                                       cell(q, 0, w, b)},
                (c.v[5] & bit) != 0);
        }
        if (e11 & bit) {
          visit(2,
                std::array<CellRef, 4>{cell(q, 0, w, b + 1), cell(q, 1, w, b + 1), cell(q, 1, w, b),
                                       cell(q, 0, w, b)},
                (c.v[3] & bit) != 0);
        }
      }
    }
  }

  // Keeps a QEF solution x inside its cell, shrunk by kDcCellMargin so that vertices of
  // neighbouring cells never coincide (which would make zero-area triangles). With several sheets
  // in the cell, each stays in the box of its own crossings as far as that box reaches into the
  // cell.
  Vec3d keep_in_cell(Vec3d x, Vec3d m, Vec3d sheet_lo, Vec3d sheet_hi, bool several) const {
    const auto& s = grid_.spacing;
    double lo[3], hi[3];
    const double slo[3] = {sheet_lo.x, sheet_lo.y, sheet_lo.z}, shi[3] = {sheet_hi.x, sheet_hi.y, sheet_hi.z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = kDcCellMargin * s[a];
      hi[a] = (1 - kDcCellMargin) * s[a];
      if (several) {
        const double l = std::max(lo[a], slo[a]), h = std::min(hi[a], shi[a]);
        if (l <= h) lo[a] = l, hi[a] = h;
      }
    }
    return keep_in_box(x, m, {lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
  }

  // The world unit normal of a sheet whose crossings' unit normals add up to normal_sum.
  Vec3f world_normal(Vec3d normal_sum) const {
    const Vec3d wn = grid_.direction * normal_sum;
    const double wl = norm(wn);
    return wl > 0 ? to_float((1.0 / wl) * wn) : Vec3f{0, 0, 1};
  }

  // The Hermite data of the cut edges of cell (i, j, k) of field f with case cs.
  template <class F>
  CellHermite cell_hermite(const Volume<F>& f, int64_t i, int64_t j, int64_t k, int cs) const {
    CellHermite h;
    for (int e = 0; e < 12; ++e) {
      const int c0 = kMcEdgeCorner[e][0];
      if ((cs >> c0 & 1) == (cs >> kMcEdgeCorner[e][1] & 1)) continue;
      const int64_t gi = i + (c0 & 1), gj = j + (c0 >> 1 & 1), gk = k + (c0 >> 2);
      store_crossing(h, e, cs, edge_crossing(f, gi, gj, gk, e / 4, o_.iso, o_.normals), i, j, k);
    }
    return h;
  }

  // The Hermite data of the cut edges of the cell at the centre of a neighbourhood key: what
  // cell_hermite gives for cell (1, 1, 1) of a 4 x 4 x 4 field holding the key, bit for bit (on a
  // 0/1 field the crossings are edge midpoints and the gradients multiples of 1/32, all exact),
  // from the key's bits: each corner's gradient once instead of once per cut edge at it.
  CellHermite key_hermite(uint64_t key, int cs) const {
    Vec3d gradient[8];
    for (int n = 0; n < 8; ++n) {
      const int x = 1 + (n & 1), y = 1 + (n >> 1 & 1), z = 1 + (n >> 2);
      auto at = [&](int di, int dj, int dk) {
        return double(key_point(key, x + di, y + dj, z + dk));
      };
      gradient[n] = o_.normals == NormalMethod::sobel ? sobel_gradient_of(at)
                                                      : central_gradient_of(at);
    }
    CellHermite h;
    for (int e = 0; e < 12; ++e) {
      const int c0 = kMcEdgeCorner[e][0], c1 = kMcEdgeCorner[e][1];
      if ((cs >> c0 & 1) == (cs >> c1 & 1)) continue;
      const int axis = e / 4;
      EdgeCrossing c;  // as edge_crossing: t = 0.5 between a 0 and a 1
      c.t = 0.5;
      c.index_point = {1 + (c0 & 1) + c.t * (axis == 0), 1 + (c0 >> 1 & 1) + c.t * (axis == 1),
                       1 + (c0 >> 2) + c.t * (axis == 2)};
      c.index_gradient = (1 - c.t) * gradient[c0] + c.t * gradient[c1];
      store_crossing(h, e, cs, c, 1, 1, 1);
    }
    return h;
  }

  // Edge e's crossing c as Hermite data of cell (i, j, k) with case cs.
  void store_crossing(CellHermite& h, int e, int cs, const EdgeCrossing& c, int64_t i, int64_t j,
                      int64_t k) const {
    const auto& s = grid_.spacing;
    const int axis = e / 4;
    h.point[e] = {(c.index_point.x - double(i)) * s[0], (c.index_point.y - double(j)) * s[1],
                  (c.index_point.z - double(k)) * s[2]};
    Vec3d n{-c.index_gradient.x / s[0], -c.index_gradient.y / s[1], -c.index_gradient.z / s[2]};
    double len = norm(n);
    if (!(len > 0)) {  // no gradient: the edge itself, pointing from inside to outside
      n = {double(axis == 0), double(axis == 1), double(axis == 2)};
      if (!(cs >> kMcEdgeCorner[e][0] & 1)) n = -1.0 * n;
      len = 1;
    }
    h.normal[e] = (1.0 / len) * n;
  }

  // The QEF vertices of every sheet of cell (i, j, k) of field f, relative to the cell; the QEFs
  // into `qefs` when given (simplification).
  template <class F>
  CellVertices solve_cell(const Volume<F>& f, int64_t i, int64_t j, int64_t k, int cs,
                          Qef* qefs) const {
    return solve_sheets(cell_hermite(f, i, j, k, cs), cs, qefs);
  }

  // The QEF vertices of every sheet of a cell with case cs and Hermite data h.
  CellVertices solve_sheets(const CellHermite& h, int cs, Qef* qefs) const {
    const auto& s = grid_.spacing;
    const DcCase& dc = table_.cases[static_cast<size_t>(cs)];
    CellVertices out;
    for (int piece = 0; piece < dc.piece_count; ++piece) {
      Qef qef;
      Vec3d normal_sum{};
      Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
      for (int t = 0; t < dc.piece_edge_count[piece]; ++t) {
        const int e = dc.piece_edges[piece][t];
        const Vec3d p = h.point[e], n = h.normal[e];
        qef.add(p, n);
        normal_sum = normal_sum + n;
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
      }
      // A cell crossed by several sheets is a configuration of single voxels touching at an edge
      // or corner, where tangent planes say nothing about a feature and the sheets' QEF minima
      // may coincide (the three quads of the tube all meet at the cell centre): each sheet takes
      // its mass point, which keeps the sheets apart.
      const Vec3d target = dc.piece_count > 1 ? qef.mass_point() : solve_qef(qef, o_.svd_eps).position;
      const Vec3d p = keep_in_cell(target, qef.mass_point(), lo, hi, dc.piece_count > 1);
      out.offset[piece] = {p.x / s[0], p.y / s[1], p.z / s[2]};
      out.normal_sum[piece] = normal_sum;
      if (qefs) qefs[piece] = qef;
    }
    return out;
  }

  // The sheets of a binary cell from its neighbourhood key (below), which gives exactly what the
  // whole field gives, as every gradient of the cell's corners reads only those points.
  CellVertices solve_key(uint64_t key, int cs, Qef* qefs) const {
    return solve_sheets(key_hermite(key, cs), cs, qefs);
  }

  // The Marching Cubes case of the cell at the centre of a neighbourhood key.
  static int case_of_key(uint64_t key) {
    int cs = 0;
    for (int n = 0; n < 8; ++n)
      cs |= int(key_point(key, 1 + (n & 1), 1 + (n >> 1 & 1), 1 + (n >> 2))) << n;
    return cs;
  }

  // The single sheet of the cell with neighbourhood `key`, solved in the frame of its mirror
  // class (SolvedNeighbourhoods) and mirrored back into `out`; false (nothing written) when the
  // class's cell does not hold exactly one sheet.
  bool solve_mirrored(uint64_t key, SolvedNeighbourhoods& table, SheetVertices& out,
                      SheetNormals& normals) const {
    const CanonicalKey c = canonical_key(key & relevant_points_[size_t(case_of_key(key))]);
    const int cs = case_of_key(c.key);
    if (pieces(cs) != 1) return false;
    const uint32_t class_entry = table.by_class.get(c.key, [&](CanonicalSheet& made) {
      const CellVertices v = solve_key(c.key, cs, nullptr);
      made = {{v.offset[0].x, v.offset[0].y, v.offset[0].z},
              {v.normal_sum[0].x, v.normal_sum[0].y, v.normal_sum[0].z}};
    });
    const CanonicalSheet& sheet = table.by_class[class_entry];
    double offset[3], normal_sum[3];
    for (int a = 0; a < 3; ++a) {
      const bool mirrored = (c.axes >> a & 1) != 0;
      offset[a] = mirrored ? 1 - sheet.offset[a] : sheet.offset[a];
      normal_sum[a] = mirrored ? -sheet.normal_sum[a] : sheet.normal_sum[a];
    }
    store_sheet(out, normals, 0, {offset[0], offset[1], offset[2]},
                {normal_sum[0], normal_sum[1], normal_sum[2]});
    return true;
  }

  // Sheet `piece` of a table entry from its index-space offset and normal sum (the normal only
  // when vertex normals are asked for).
  void store_sheet(SheetVertices& out, SheetNormals& normals, int piece, Vec3d offset,
                   Vec3d normal_sum) const {
    const auto& s = grid_.spacing;
    const Vec3f o =
        to_float(grid_.direction * Vec3d{offset.x * s[0], offset.y * s[1], offset.z * s[2]});
    float* to = out.offset[piece];
    to[0] = o.x, to[1] = o.y, to[2] = o.z;
    if (!normals_) return;
    const Vec3f n = world_normal(normal_sum);
    float* tn = normals.normal[piece];
    tn[0] = n.x, tn[1] = n.y, tn[2] = n.z;
  }

  // The columns of the 16 rows around one row of cells (rows (j - 1 + y, k - 1 + z) at
  // n = y + 4 z), 16 bits per grid point x (inside_bits.hpp's column_codes), for one word of cells
  // and the points beyond it its cells read (x - 1 .. x + 2): code(b) for b = -1 .. 65 is column
  // 64 w + b, and the four of cell b's neighbourhood are consecutive in memory, one 64-bit load.
  // (Taken a column at a time from a cache of three words, the keys cost a fifth of the phantom's
  // Dual Contouring.)
  class WordColumns {
   public:
    WordColumns(const uint64_t* const* rows, int64_t nx) : rows_(rows), nx_(nx) {}
    // The columns of word w, and those past its ends that the cells in `cells` read.
    void load(int64_t w, uint64_t cells) {
      // The columns of the word the cells read: b - 1 .. b + 2 for every cell b. Most words of a
      // surface have a few cells, and then these few columns are taken from the interleaved bytes
      // (column_bytes) rather than all 64.
      const uint64_t wanted = cells >> 1 | cells | cells << 1 | cells << 2;
      if (std::popcount(wanted) > kFewColumns) {
        column_codes(rows_, w, codes_ + 1);
      } else {
        column_bytes(rows_, w, bytes_);
        for (uint64_t m = wanted; m != 0; m &= m - 1) {
          const int b = std::countr_zero(m);
          codes_[b + 1] = column_code(bytes_, b);
        }
      }
      codes_[0] = (cells & 1) ? column(64 * w - 1) : 0;
      if (cells >> 62) codes_[65] = column(64 * w + 64), codes_[66] = column(64 * w + 65);
    }
    // Columns b - 1 .. b + 2 (b = 0 .. 63), 16 bits each, b - 1 lowest.
    uint64_t four(int b) const {
      uint64_t v;
      std::memcpy(&v, codes_ + b, sizeof v);
      return v;
    }

   private:
    uint16_t column(int64_t x) const {  // 0 outside the grid
      return x < 0 || x >= nx_ ? 0 : column_at(rows_, x);
    }
    static constexpr int kFewColumns = 24;
    const uint64_t* const* rows_;
    const int64_t nx_;
    ColumnBytes bytes_;
    uint16_t codes_[68] = {};  // code(b) at b + 1
  };

  // The 4 x 4 x 4 grid points around cell b of the word `columns` holds (offsets -1 .. 2), bit
  // (n + 16 x) set when point (x, y, z) is inside (n = y + 4 z), for a cell at least one point from
  // the border. Only the points the gradients read are kept (key_mask_), so cells that differ
  // elsewhere share their entry. Never 0 for a non-trivial cell.
  uint64_t neighbourhood(const WordColumns& columns, int b) const {
    return columns.four(b) & key_mask_;
  }
  // Pass 3: the sheet vertices.
  void emit_vertices(TriMesh& mesh) {
    std::atomic<int64_t> rows_done{0};
    // The scene's solved neighbourhoods, or this part's own.
    std::optional<DcNeighbourhoods> own;
    DcNeighbourhoods* solved = nullptr;
    if (binary_) {
      solved = solved_ ? solved_ : &own.emplace(grid_, o_);
      if (!solved->tables->fits(grid_, o_)) {
        throw std::logic_error(
            "dual contouring: neighbourhoods solved for another grid or options");
      }
    }
    // A cell's first corner in world space: its row's plus x steps along x.
    const Vec3d step_x = grid_.direction * Vec3d{grid_.spacing[0], 0, 0};
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 16), [&](const auto& range) {
      throw_if_cancelled(progress_);
      SolvedNeighbourhoods* table = solved ? &solved->tables->threads.local() : nullptr;
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        if (vertex_first_[size_t(r) + 1] == vertex_first_[size_t(r)]) continue;  // no cells
        const int64_t j = r % cy_, k = r / cy_;
        const bool rows_inside = j >= 1 && k >= 1 && j + 2 < ny_ && k + 2 < nz_;
        const uint64_t* around[16];
        if (rows_inside) {
          for (int n = 0; n < 16; ++n) around[n] = bits_.row(j - 1 + (n & 3), k - 1 + (n >> 2));
        }
        WordColumns columns(around, nx_);
        // Keys are made for the cells that may be keyed and will be.
        const bool keys = rows_inside && (table != nullptr || f_ == nullptr);
        const Vec3d row_corner = grid_.to_world({0, double(j), double(k)});
        uint32_t id = vertex_first_[size_t(r)];
        const CellWord* row = words(j, k);
        const CornerRows corner_rows = corners(j, k);
        for (int64_t w = 0; w < cw_; ++w) {
          if (row[w].cells == 0) continue;
          const CornerWords c = corner_rows.at(w);
          if (keys) columns.load(w, row[w].cells);
          for (uint64_t m = row[w].cells; m != 0; m &= m - 1) {
            const int b = std::countr_zero(m);
            const int64_t x = 64 * w + b;
            // A cell that is not rare holds one sheet; its case is only needed to solve it.
            const auto cs = [&] { return c.case_of(b); };
            const int n = (row[w].rare >> b & 1) ? pieces(cs()) : 1;
            const bool keyed = rows_inside && x >= 1 && x + 2 < nx_;
            if (keyed && table && n <= SheetVertices::kPieces) {  // most cells
              const uint64_t key = neighbourhood(columns, b);
              const uint32_t entry = table->by_key.get(key, [&](SheetVertices& out) {
                SheetNormals normals;
                if (n != 1 || !solve_mirrored(key, *table, out, normals)) {
                  const CellVertices full = solve_key(key, cs(), nullptr);
                  for (int p = 0; p < n; ++p)
                    store_sheet(out, normals, p, full.offset[p], full.normal_sum[p]);
                }
                if (normals_) table->normals.push_back(normals);
              });
              const SheetVertices& v = table->by_key[entry];
              const Vec3d corner = row_corner + double(x) * step_x;
              for (int p = 0; p < n; ++p) {
                const float* o = v.offset[p];
                mesh.positions[id + p] = to_float(corner + Vec3d{o[0], o[1], o[2]});
                if (normals_) {
                  const float* nn = table->normals[entry].normal[p];
                  mesh.normals[id + p] = {nn[0], nn[1], nn[2]};
                }
              }
            } else {
              // Solved for this cell alone (not inlined: the loop above stays small).
              auto solve_alone = [&]() __attribute__((noinline)) {
                Qef* qefs = qefs_.empty() ? nullptr : &qefs_[id];
                if (!keyed && f_ == nullptr)
                  throw std::logic_error("dual contouring: a part's cell at its border");
                const CellVertices v = f_ != nullptr
                                           ? solve_cell(*f_, x, j, k, cs(), qefs)
                                           : solve_key(neighbourhood(columns, b), cs(), qefs);
                for (int p = 0; p < n; ++p) {
                  const Vec3d d{double(x), double(j), double(k)};
                  mesh.positions[id + p] = to_float(grid_.to_world(d + v.offset[p]));
                  if (normals_) mesh.normals[id + p] = world_normal(v.normal_sum[p]);
                }
              };
              solve_alone();
            }
            id += static_cast<uint32_t>(n);
          }
        }
      }
      progress_.update(0.5 * double(rows_done += range.size()) / double(rows()));
    });
  }

  // The polygon of the sheets around an edge along `axis` from its four cells, wound
  // counter-clockwise seen from outside.
  Polygon polygon(int axis, const std::array<CellRef, 4>& quadrant, bool inside_at_start) const {
    Polygon p;
    for (int q = 0; q < 4; ++q) {
      const CellRef& cell = quadrant[q];
      if (cell.cs == kOneSheet) {
        p.vertex[p.n] = cell.first_vertex;
        p.quadrant[p.n++] = q;
        continue;
      }
      const DcCase& dc = table_.cases[static_cast<size_t>(cell.cs)];
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
    if (inside_at_start == mirrored_) {
      std::reverse(p.vertex.begin(), p.vertex.begin() + p.n);
      std::reverse(p.quadrant.begin(), p.quadrant.begin() + p.n);
    }
    return p;
  }

  // Triangles (and centroid vertices, 0 or 1) the polygon of an edge becomes.
  static std::pair<uint64_t, uint64_t> polygon_cost(const Polygon& p) {
    if (p.n == 4) return {2, 0};
    if (triangulable(p)) return {uint64_t(p.n - 2), 0};
    return {uint64_t(p.n), 1};
  }

  // Pass 2: the triangles per row corrected where a polygon next to a rare cell is not a quad,
  // and the centroid vertices (into extra_first_[r + 1]); the rows that own a cut edge without
  // its four cells throw. Only the rows next to a rare cell, or short, are looked at. Runs on the
  // counts, before prefix_sums: the polygons' vertex ids are not known yet, and their cost only
  // depends on their shape.
  void count_polygons() {
    const size_t n = static_cast<size_t>(rows());
    extra_first_.assign(n + 1, 0);
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 256), [&](const auto& range) {
      throw_if_cancelled(progress_);
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        const int64_t j = r % cy_, k = r / cy_;
        if (row_short_[size_t(r)]) {
          owned_edges<Edges::all_checked>(
              j, k, [](int, const auto&, bool) {});  // throws for the cut edge at fault
        }
        bool rare = false;
        for (int q = 0; q < 4; ++q) {
          const int64_t jr = j + (q & 1), kr = k + (q >> 1);
          rare = rare || (jr < cy_ && kr < cz_ && row_rare_[row_index(jr, kr)]);
        }
        if (!rare) continue;
        uint64_t triangles = triangle_first_[size_t(r) + 1], extra = 0;
        owned_edges<Edges::next_to_rare>(j, k, [&](int axis, const auto& quadrant, bool in) {
          const auto [t, e] = polygon_cost(polygon(axis, quadrant, in));
          triangles += t - 2;  // a polygon has four vertices or more
          extra += e;
        });
        triangle_first_[size_t(r) + 1] = count32(triangles);
        extra_first_[size_t(r) + 1] = count32(extra);
      }
    });
  }

  // The rows' counts into their first ids: vertex_first_[r] is row r's first sheet vertex,
  // triangle_first_[r] its first triangle, extra_first_[r] its first centroid vertex (after the
  // sheets); entry rows() is the total. Throws where the sheets and centroid vertices, or the
  // triangles, are more than 32-bit ids can number.
  void prefix_sums() {
    uint64_t sheets = 0, triangles = 0, extra = 0;
    for (size_t r = 0; r < static_cast<size_t>(rows()); ++r) {
      sheets += vertex_first_[r + 1];
      triangles += triangle_first_[r + 1];
      extra += extra_first_[r + 1];
      mesh_id_count(sheets + extra, kWho);
      vertex_first_[r + 1] = static_cast<uint32_t>(sheets);
      triangle_first_[r + 1] = count32(triangles);
      extra_first_[r + 1] = static_cast<uint32_t>(extra);
    }
  }
  static constexpr const char* kWho = "dual contouring";
  // One row's count, as the row arrays keep it.
  static uint32_t count32(uint64_t n) { return mesh_id_count(n, kWho); }

  // Pass 4: the polygons, split into triangles.
  void emit_polygons(TriMesh& mesh) {
    std::atomic<int64_t> rows_done{0};
    const uint64_t sheets = vertex_first_.back();
    tbb::parallel_for(tbb::blocked_range<int64_t>(0, rows(), 64), [&](const auto& range) {
      throw_if_cancelled(progress_);
      std::vector<std::array<int, 3>> tris;
      // The quads waiting for their diagonals, split a few hundred at a time. (A fixed array and
      // the visitor inlined: as a std::vector filled by a called visitor, the bookkeeping of each
      // quad cost a sixth of Dual Contouring on the phantom.)
      std::array<PendingQuad, 512> quads;
      size_t pending = 0;
      for (int64_t r = range.begin(); r < range.end(); ++r) {
        if (triangle_first_[size_t(r) + 1] == triangle_first_[size_t(r)]) continue;
        uint32_t* out = mesh.indices.data() + 3 * size_t{triangle_first_[size_t(r)]};
        uint32_t extra = static_cast<uint32_t>(sheets + extra_first_[size_t(r)]);
        // A quad waiting for its diagonal; split_quads writes its six indices. Always inlined: the
        // pass's hot path (the compiler once stopped inlining it, and the phantom lost 7 %).
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
          const Polygon p = polygon(axis, quadrant, in);
          auto pos = [&](int a) { return to_double(mesh.positions[p.vertex[a]]); };
          if (p.n == 4) {
            quad(p.vertex.data());
            return;
          }
          auto rho = [&](int a, int b, int c) { return radii_ratio(pos(a), pos(b), pos(c)); };
          if (triangulate(p, rho, tris)) {
            for (const auto& t : tris) {
              out[0] = p.vertex[t[0]], out[1] = p.vertex[t[1]], out[2] = p.vertex[t[2]];
              out += 3;
            }
            return;
          }
          // No manifold-safe diagonals: a fan around a new vertex at the polygon's centroid.
          Vec3d centre{}, normal{};
          for (int a = 0; a < p.n; ++a) {
            centre = centre + pos(a);
            if (normals_) normal = normal + to_double(mesh.normals[p.vertex[a]]);
          }
          mesh.positions[extra] = to_float((1.0 / p.n) * centre);
          if (normals_) {
            const double nl = norm(normal);
            mesh.normals[extra] = nl > 0 ? to_float((1.0 / nl) * normal) : Vec3f{0, 0, 1};
          }
          for (int a = 0; a < p.n; ++a) {
            out[0] = extra, out[1] = p.vertex[a], out[2] = p.vertex[(a + 1) % p.n];
            out += 3;
          }
          ++extra;
        };
        const int64_t j = r % cy_, k = r / cy_;
        owned_edges<Edges::all>(
            j, k, [&](int axis, const auto& quadrant, bool in) __attribute__((always_inline)) {
              const bool reverse = in == mirrored_;  // polygon()'s winding, for a quad inline
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
      progress_.update(0.5 + 0.5 * double(rows_done += range.size()) / double(rows()));
    });
  }

  // The cells with sheets and their first vertex (for the simplification), in vertex order.
  std::vector<SurfaceCell> surface_cells() const {
    std::vector<SurfaceCell> out;
    for (int64_t r = 0; r < rows(); ++r) {
      const int64_t j = r % cy_, k = r / cy_;
      uint32_t id = vertex_first_[size_t(r)];
      const CellWord* row = words(j, k);
      for (int64_t w = 0; w < cw_; ++w) {
        for (uint64_t m = row[w].cells; m != 0; m &= m - 1) {
          const int64_t x = 64 * w + std::countr_zero(m);
          const int cs = case_at(x, j, k);
          if (pieces(cs) > 0) out.push_back({int32_t(x), int32_t(j), int32_t(k), uint8_t(cs), id});
          id += static_cast<uint32_t>(pieces(cs));
        }
      }
    }
    return out;
  }

  const Volume<T>* f_;
  const InsideBits& bits_;
  const Grid& grid_;
  const bool binary_;
  const bool normals_;
  const DcOptions& o_;
  const DcTable& table_;
  Progress& progress_;
  DcNeighbourhoods* const solved_;  // the scene's solved neighbourhoods, or nullptr
  const int64_t nx_, ny_, nz_, cx_, cy_, cz_, cw_;
  const bool mirrored_;  // a mirrored grid reverses every winding
  const std::array<uint64_t, 256>& relevant_points_;  // per case (kRelevantPoints)
  // The points any cell's gradients read, relevant_points_ over all cases: Sobel's 3 x 3 x 3
  // around each corner are all 64, central differences' six neighbours of each corner the 32
  // points with at most one coordinate at -1 or 2.
  const uint64_t key_mask_;
  std::array<bool, 256> rare_{};
  std::vector<CellWord> words_;           // per row of cells, cw_ words
  std::unique_ptr<uint32_t[]> word_first_;  // per word with cells: the row's sheets before it
  std::vector<uint8_t> row_rare_;         // per row of cells: any rare cell
  std::vector<uint8_t> row_short_;        // per row of cells: a cut edge without its four cells
  // 32-bit like the ids they count to (prefix_sums throws past them): half the bytes per row.
  std::vector<uint32_t> vertex_first_;    // per row: its first sheet vertex
  std::vector<uint32_t> triangle_first_;  // per row: its first triangle
  std::vector<uint32_t> extra_first_;     // per row: its first centroid vertex (after the sheets)
  std::vector<Qef> qefs_;  // per sheet vertex, kept only for the simplification
};

// A 0/1 field contoured between 0 and 1, whose cells the neighbourhood cache may serve.
template <class T>
bool is_binary(const Volume<T>& field, double iso) {
  if constexpr (!std::is_same_v<T, uint8_t>) {
    return false;
  } else {
    if (!(iso > 0 && iso < 1)) return false;
    uint8_t any_above = 0;
    for (uint8_t v : field.voxels) any_above |= v & 0xfe;
    return any_above == 0;
  }
}

}  // namespace

DcNeighbourhoods::DcNeighbourhoods(const Grid& grid, const DcOptions& options)
    : tables(new Tables{grid.spacing,
                        grid.direction,
                        options.connectivity,
                        options.normals,
                        options.svd_eps,
                        options.vertex_normals,
                        {}}) {}

DcNeighbourhoods::~DcNeighbourhoods() = default;

template <class T>
TriMesh dual_contouring(const Volume<T>& field, const DcOptions& options, Progress& progress) {
  const auto& d = field.grid.dims;
  if (d[0] < 2 || d[1] < 2 || d[2] < 2) return {};
  const InsideBits bits = inside_bits(field, options.iso, progress);
  return Extractor<T>(&field, bits, field.grid, is_binary(field, options.iso), options, progress)
      .run();
}

TriMesh dual_contouring(const Grid& grid, const Components& components, const Component& component,
                        const DcOptions& options, Progress& progress, DcNeighbourhoods* solved) {
  DcOptions o = options;
  o.iso = 0.5;
  const InsideBits bits = inside_bits(components, component);
  const Grid part_grid = component_grid(grid, component);
  return Extractor<uint8_t>(nullptr, bits, part_grid, true, o, progress, solved).run();
}

template TriMesh dual_contouring(const Volume<uint8_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<int32_t>&, const DcOptions&, Progress&);
template TriMesh dual_contouring(const Volume<float>&, const DcOptions&, Progress&);

}  // namespace segmesh
