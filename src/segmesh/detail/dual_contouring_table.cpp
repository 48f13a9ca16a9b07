#include "segmesh/detail/dual_contouring_table.hpp"

#include <algorithm>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "segmesh/detail/marching_cubes_table.hpp"
#include "segmesh/vec3.hpp"

namespace segmesh {

namespace {

using Cycle = std::vector<int>;
using Chord = std::pair<int, int>;  // undirected, first < second

Chord chord(int a, int b) { return {std::min(a, b), std::max(a, b)}; }

Vec3d midpoint(int e) {
  const auto& c0 = kMcCornerOffset[kMcEdgeCorner[e][0]];
  const auto& c1 = kMcCornerOffset[kMcEdgeCorner[e][1]];
  return {0.5 * (c0[0] + c1[0]), 0.5 * (c0[1] + c1[1]), 0.5 * (c0[2] + c1[2])};
}

[[noreturn]] void fail(int cs, const std::string& what) {
  throw std::logic_error("dual contouring table, case " + std::to_string(cs) + ": " + what);
}

// The face of the boundary edge a -> b of a piece, or -1 when it is a chord.
int segment_face(int a, int b, const std::set<Chord>& chords) {
  return chords.count(chord(a, b)) ? -1 : mc_shared_face(a, b);
}

// Splits pieces that hold both segments of one face until none does.
void split_doubled_faces(int cs, std::vector<Cycle>& pieces, std::set<Chord>& chords) {
  for (size_t p = 0; p < pieces.size(); ++p) {
    const Cycle c = pieces[p];
    const int n = static_cast<int>(c.size());
    int first = -1, second = -1;
    for (int i = 0; i < n && second < 0; ++i) {
      const int fi = segment_face(c[i], c[(i + 1) % n], chords);
      if (fi < 0) continue;
      for (int j = i + 1; j < n; ++j) {
        if (segment_face(c[j], c[(j + 1) % n], chords) == fi) {
          first = i;
          second = j;
          break;
        }
      }
    }
    if (second < 0) continue;
    // Chord from the path after the first segment to the path after the second one.
    auto adjacent = [&](int i, int j) { return (i + 1) % n == j || (j + 1) % n == i; };
    double best = std::numeric_limits<double>::infinity();
    int bx = -1, by = -1;
    for (int x = first + 1; x <= second; ++x) {
      for (int k = second + 1; k <= first + n; ++k) {
        const int y = k % n;
        if (adjacent(x, y) || chords.count(chord(c[x], c[y]))) continue;
        const double d = norm(midpoint(c[x]) - midpoint(c[y]));
        if (d < best - 1e-12) {
          best = d;
          bx = x;
          by = y;
        }
      }
    }
    if (bx < 0) fail(cs, "no chord splits a doubled face");
    Cycle d1, d2;  // y .. x through the first segment; x .. y through the second
    for (int k = by;; k = (k + 1) % n) {
      d1.push_back(c[k]);
      if (k == bx) break;
    }
    for (int k = bx;; k = (k + 1) % n) {
      d2.push_back(c[k]);
      if (k == by) break;
    }
    chords.insert(chord(c[bx], c[by]));
    pieces[p] = d1;
    pieces.push_back(d2);
    --p;  // look at the shortened piece again
  }
}

// Three quads between the two triangles of the 26-connectivity tube; walking forwards along one
// cycle goes with walking backwards along the other.
void split_tube(const Cycle& a, const Cycle& b, std::vector<Cycle>& pieces,
                std::set<Chord>& chords) {
  double best = std::numeric_limits<double>::infinity();
  int best_t = 0;
  for (int t = 0; t < 3; ++t) {
    double length = 0;
    for (int i = 0; i < 3; ++i) length += norm(midpoint(a[i]) - midpoint(b[((t - i) % 3 + 3) % 3]));
    if (length < best - 1e-12) {
      best = length;
      best_t = t;
    }
  }
  auto bi = [&](int k) { return b[((k % 3) + 3) % 3]; };
  for (int i = 0; i < 3; ++i) {
    pieces.push_back({a[i], a[(i + 1) % 3], bi(best_t - i - 1), bi(best_t - i)});
    chords.insert(chord(a[i], bi(best_t - i)));
  }
}

int face_of_edge_side(int e, int axis) {
  const int ea = e >> 2, bits = e & 3;
  // Coordinates of the edge along the two other axes, ascending axis order.
  const int lo_axis = ea == 0 ? 1 : 0;
  const int coordinate = axis == lo_axis ? (bits & 1) : (bits >> 1);
  return 2 * axis + coordinate;
}

DcCase build_case(int cs, int connectivity) {
  const McCaseTopology topology = mc_case_topology(cs, connectivity);
  std::vector<Cycle> pieces;
  std::set<Chord> chords;
  if (topology.tube) {
    split_tube(topology.cycles[0], topology.cycles[1], pieces, chords);
  } else {
    pieces = topology.cycles;
  }
  split_doubled_faces(cs, pieces, chords);
  if (pieces.size() > static_cast<size_t>(kDcMaxPieces)) fail(cs, "too many pieces");

  DcCase out;
  out.piece_count = static_cast<uint8_t>(pieces.size());
  for (size_t p = 0; p < pieces.size(); ++p) {
    std::set<int> seen(pieces[p].begin(), pieces[p].end());
    if (seen.size() != pieces[p].size() || pieces[p].size() < 3) fail(cs, "piece is not a disk");
    out.piece_edge_count[p] = static_cast<uint8_t>(pieces[p].size());
    for (size_t k = 0; k < pieces[p].size(); ++k) out.piece_edges[p][k] = int8_t(pieces[p][k]);
  }
  // Every chord bounds exactly two pieces, in opposite directions; no two pieces share two chords.
  std::set<std::pair<int, int>> piece_pairs;
  for (const Chord& ch : chords) {
    std::vector<int> holders;
    for (size_t p = 0; p < pieces.size(); ++p) {
      const Cycle& c = pieces[p];
      for (size_t k = 0; k < c.size(); ++k) {
        if (chord(c[k], c[(k + 1) % c.size()]) == ch) holders.push_back(int(p));
      }
    }
    if (holders.size() != 2) fail(cs, "a chord does not bound two pieces");
    if (!piece_pairs.insert({holders[0], holders[1]}).second) fail(cs, "pieces share two chords");
  }

  // The pieces around each cut edge, from its face perpendicular to axis (a+1)%3 to the one
  // perpendicular to (a+2)%3, walking over the chords that end at the edge.
  for (int e = 0; e < 12; ++e) {
    const int a = e >> 2;
    const int from_face = face_of_edge_side(e, (a + 1) % 3);
    const int to_face = face_of_edge_side(e, (a + 2) % 3);
    // Per piece holding e: the faces (or chords, -1) of its two boundary edges at e.
    struct At {
      int piece, in_face, out_face, in_other, out_other;
    };
    std::vector<At> at;
    for (size_t p = 0; p < pieces.size(); ++p) {
      const Cycle& c = pieces[p];
      const int n = static_cast<int>(c.size());
      for (int k = 0; k < n; ++k) {
        if (c[k] != e) continue;
        const int prev = c[(k + n - 1) % n], next = c[(k + 1) % n];
        at.push_back({int(p), segment_face(prev, e, chords), segment_face(e, next, chords), prev,
                      next});
      }
    }
    if (at.empty()) continue;
    auto holds_face = [&](const At& x, int face) { return x.in_face == face || x.out_face == face; };
    int current = -1;
    for (size_t i = 0; i < at.size(); ++i) {
      if (holds_face(at[i], from_face)) current = int(i);
    }
    if (current < 0) fail(cs, "no piece holds a cut edge's face segment");
    std::vector<int> order;
    int came_from = -1;  // the other end of the chord we arrived by
    while (true) {
      order.push_back(at[current].piece);
      if (holds_face(at[current], to_face)) break;
      if (order.size() > 3) fail(cs, "more than three pieces around an edge");
      // Leave by the chord that is not the one we came in by.
      const At& x = at[current];
      const int other = (x.in_face < 0 && x.in_other != came_from) ? x.in_other : x.out_other;
      int next = -1;
      for (size_t i = 0; i < at.size(); ++i) {
        if (int(i) == current) continue;
        if (at[i].in_other == other || at[i].out_other == other) next = int(i);
      }
      if (next < 0) fail(cs, "pieces around an edge do not chain");
      came_from = other;
      current = next;
    }
    if (order.size() != at.size()) fail(cs, "a piece around an edge is not on its chain");
    out.around_count[e] = static_cast<uint8_t>(order.size());
    for (size_t i = 0; i < order.size(); ++i) out.around[e][i] = static_cast<int8_t>(order[i]);
  }
  return out;
}

}  // namespace

DcTable build_dc_table(int connectivity) {
  require_connectivity(connectivity, "dual contouring");
  DcTable table;
  table.connectivity = connectivity;
  for (int cs = 0; cs < 256; ++cs) table.cases[cs] = build_case(cs, connectivity);
  return table;
}

const DcTable& dc_table(int connectivity) {
  require_connectivity(connectivity, "dual contouring");
  static const DcTable tables[3] = {build_dc_table(6), build_dc_table(18), build_dc_table(26)};
  return tables[connectivity_index(connectivity)];
}

}  // namespace segmesh
