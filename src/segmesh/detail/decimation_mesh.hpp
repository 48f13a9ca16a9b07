// The working state of decimation (decimation.hpp): the labelled surface under change and what
// its three operations share (edge collapse in decimation.cpp; edge flips and tangential
// relaxation in detail/decimation_passes.hpp): positions in double, vertex roles, quadrics, the
// live triangles of every vertex, and the witnesses that bound the distance from the original
// vertices to the surface. Internal to the core: included by decimation.cpp and
// decimation_passes.cpp only.
//
// Witnesses. Every original vertex keeps a witness, a live triangle within the bound;
// `witnesses` lists them per triangle. A change (a collapse, a flip, a vertex moved) that alters
// some triangles needs a new witness for every original vertex those witness: among the triangles
// near the change as they will be, else among those one ring further. The checks below find
// them and keep them in this thread's scratch (`pending`); commit_witnesses makes them the witnesses once the caller
// makes the change.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdlib>
#include <deque>
#include <memory>
#include <new>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "segmesh/detail/ordered_triangle_tree.hpp"
#include "segmesh/detail/quadric.hpp"
#include "segmesh/detail/smoothing_filters.hpp"
#include "segmesh/labelled_surface.hpp"

namespace segmesh {

// No triangle may turn by more than 60 degrees in a collapse or a flip.
inline constexpr double kDecimationMaxTurnCos = 0.5;
// A sliver, as issue 36 counts them: radii ratio below this. The sliver pass collapses them; a
// flip that removes one may use more of the bound.
inline constexpr double kDecimationSliverRho = 0.05;

// Lists of vertex or triangle ids for the checks, reused: a check allocates nothing once the
// lists have grown (the allocations of fresh lists were a fifth of the decimation's time).
class ListPool {
 public:
  using List = std::vector<uint32_t>;
  // A cleared list, returned to the pool when the lease ends; bind it to a name.
  class Lease {
   public:
    Lease(ListPool& pool, List& list) : pool_(&pool), list_(&list) {}
    Lease(Lease&& o) noexcept : pool_(std::exchange(o.pool_, nullptr)), list_(o.list_) {}
    Lease(const Lease&) = delete;
    Lease& operator=(const Lease&) = delete;
    Lease& operator=(Lease&&) = delete;
    ~Lease() {
      if (pool_) pool_->free_.push_back(list_);
    }
    List& operator*() const { return *list_; }
    List* operator->() const { return list_; }

   private:
    ListPool* pool_;
    List* list_;
  };
  Lease take() {
    if (free_.empty()) free_.push_back(&all_.emplace_back());
    List& list = *free_.back();
    free_.pop_back();
    list.clear();
    return Lease(*this, list);
  }

 private:
  std::deque<List> all_;  // stable addresses
  std::vector<List*> free_;
};

// The live triangles of every vertex in one pooled array, each vertex's list a run of it with
// room to grow (a list that outgrows its room moves to the end, with twice the room). Built in
// vertex order, so the lists of neighbouring vertices share cache lines; per-vertex vectors were
// millions of small heap blocks, a miss for the header and another for the block. A list keeps
// its order through push_back, erase and erase_if. Only reserve and push_back may move lists
// (and so invalidate every span of the pool). In the block phase of decimation.cpp (one thread
// per block) the pool does not grow: a list moves only into room taken beforehand (try_room).
class VertexTriangles {
 public:
  // The triangles of `indices` (nt triangles) per corner, in triangle order.
  void build(size_t nv, const std::vector<uint32_t>& indices, size_t nt);
  std::span<const uint32_t> operator[](uint32_t v) const {
    return {data_.data() + head_[v].start, head_[v].size};
  }
  // Room for `more` entries in v's list without a move.
  void reserve(uint32_t v, uint32_t more) {
    if (head_[v].size + more > head_[v].cap) move(v, head_[v].size + more);
  }
  size_t entries() const { return data_.size(); }  // in the lists and their room
  // The block phase: room for moved lists, taken for each block before it starts (so what a
  // block's moves find does not depend on the other blocks).
  struct Room {
    size_t next = 0, end = 0;
  };
  Room take_room(size_t entries);
  // Room for `size` entries in v's list, from `room` when the list must move: false when that
  // is used up (the list stays where it is). For the block phase: threads work side by side,
  // each in its own vertices' lists and its own room.
  bool try_room(uint32_t v, uint32_t size, Room& room);
  void push_back(uint32_t v, uint32_t t) {
    reserve(v, 1);
    Head& h = head_[v];
    data_[h.start + h.size++] = t;
  }
  template <class Pred>
  void erase_if(uint32_t v, Pred&& pred) {
    Head& h = head_[v];
    uint32_t* b = data_.data() + h.start;
    h.size = uint32_t(std::remove_if(b, b + h.size, pred) - b);
  }
  void erase(uint32_t v, uint32_t t) {
    erase_if(v, [t](uint32_t x) { return x == t; });
  }
  void clear(uint32_t v) { head_[v].size = 0; }
  void prefetch_head(uint32_t v) const { __builtin_prefetch(&head_[v]); }
  void prefetch_list(uint32_t v) const { __builtin_prefetch(data_.data() + head_[v].start); }

 private:
  struct Head {
    uint32_t start = 0, size = 0, cap = 0;
  };
  void move(uint32_t v, uint32_t need);
  uint32_t relocate(uint32_t v, uint32_t need, size_t start);  // returns the new room
  std::vector<Head> head_;
  std::vector<uint32_t> data_;
};

// A triangle of a witness check as it will be, and its box.
struct FanTriangle {
  uint32_t t;
  std::array<Vec3d, 3> p;
  Vec3d lo, hi;
};

// An original vertex a triangle witnesses: its position and an upper bound of its distance to
// the triangle (rounded up to float), kept with the triangle, so a check reads one list.
struct Witnessed {
  Vec3f position;
  float distance;
};

// Per triangle, the original vertices it witnesses (Witnessed) and the bounds of their distance
// (DecimationMesh::witnesses), in 32 bytes: the common check reads `reach` only, and the rest
// needs the offset and the list's header, on the same cache line (they were three arrays, a
// miss each).
class alignas(32) TriangleWitnesses {
 public:
  double reach = 0, offset = 0;
  TriangleWitnesses() = default;
  TriangleWitnesses(const TriangleWitnesses&) = delete;
  TriangleWitnesses& operator=(const TriangleWitnesses&) = delete;
  ~TriangleWitnesses() { std::free(data_); }
  const Witnessed* begin() const { return data_; }
  const Witnessed* end() const { return data_ + size_; }
  void clear() { size_ = 0; }
  void push_back(const Witnessed& w) {
    if (size_ == cap_) {
      cap_ = cap_ == 0 ? 2 : 2 * cap_;
      void* grown = std::realloc(data_, sizeof(Witnessed) * cap_);
      if (!grown) throw std::bad_alloc();
      data_ = static_cast<Witnessed*>(grown);
    }
    data_[size_++] = w;
  }

 private:
  Witnessed* data_ = nullptr;
  uint32_t size_ = 0, cap_ = 0;
};
static_assert(sizeof(TriangleWitnesses) == 32);

// A new witness found by a check: the original vertex's position, its triangle and an upper
// bound of its distance to that triangle as it will be.
struct PendingWitness {
  Vec3f position;
  uint32_t t;
  double distance;
};

// A triangle a check changes: `whole` when all its witnesses stay within the bound by its reach
// plus `shift` (then its list is left as it is), else its list is made again from `pending`.
struct ChangedTriangle {
  uint32_t t;
  bool whole;
  double shift;
};

// What the checks build and throw away, one per thread (the block phase of decimation.cpp
// checks collapses on every core): id lists, a check's candidate witnesses (`fan`), and its new
// witnesses and changed triangles for commit_witnesses.
struct DecimationScratch {
  ListPool pool;
  std::vector<FanTriangle> fan;
  std::vector<PendingWitness> pending;
  std::vector<ChangedTriangle> pending_changed;
};

struct DecimationMesh {
  // Positions, roles (surface_roles with either winding), quadrics (every triangle's plane,
  // weight 1/3, on its corners), triangle lists and witnesses of `surface`, kept until compact.
  // Without `witnessing` (no error bound: a triangle budget alone) there are no witnesses: with
  // no bound they only kept every original vertex on some live triangle, which every collapse
  // the other checks allow leaves but one, which collapse_keeps_witnesses still refuses.
  explicit DecimationMesh(LabelledSurface& surface, bool witnessing = true);

  LabelledSurface& s;
  bool witnessing = true;
  std::vector<Vec3d> pos;
  std::vector<SmoothRole> role;
  std::vector<char> junction_vertex;  // s.junction_vertices and the vertices they merged into
  std::vector<Quadric> quadric;
  VertexTriangles tris;  // per vertex; may hold dead triangles until pruned
  std::vector<char> alive_tri, alive_vertex;
  // Per triangle the original vertices it witnesses, with an upper bound of their distance to
  // it: the entry's distance plus the triangle's offset. A change
  // that moves one corner of a triangle by d moves every point of it by at most d, so a witness
  // whose bound plus d stays within the limit needs no projection. The reach bounds them all
  // (0 for none): when the reach plus d is within the limit, the change adds d to the offset
  // and the reach and reads no list, the common case.
  std::vector<TriangleWitnesses> witnesses;
  // The surface as it was before any change (a copy of its triangles and a tree on them), with
  // an error bound only: the passes after the collapses (detail/decimation_passes.hpp) check
  // the triangles they make against it, as the witnesses bound only the other direction.
  struct Original {
    std::vector<Vec3f> positions;
    std::vector<uint32_t> indices;
    std::optional<OrderedTriangleTree> tree;
    // Per vertex, the original triangle nearest to its last query (at first one of its own):
    // where the next search near it starts.
    std::vector<uint32_t> hint;
  };
  std::unique_ptr<Original> original;
  // Whether p, a point of a triangle of vertex v, is within sqrt(limit2) of the original surface
  // (true without one). Not thread-safe: it updates v's hint.
  bool near_original(const Vec3d& p, double limit2, uint32_t v);
  // This thread's scratch.
  static DecimationScratch& scratch() {
    thread_local DecimationScratch here;
    return here;
  }
  static ListPool& pool() { return scratch().pool; }

  // Prefetches for a collapse of v soon, in stages, each for a candidate nearer than the stage
  // before, so that what it reads has come: 0, v's position, quadric, role and list header; 1,
  // its list; 2, its triangles' corners, liveness, sides and witness records; 3, the positions
  // of those corners.
  void prefetch(int stage, uint32_t v) const {
    if (stage == 0) {
      __builtin_prefetch(&pos[v]);
      __builtin_prefetch(&quadric[v]);
      __builtin_prefetch(&role[v]);
      tris.prefetch_head(v);
    } else if (stage == 1) {
      tris.prefetch_list(v);
    } else if (stage == 2) {
      for (uint32_t t : tris[v]) {
        __builtin_prefetch(&s.mesh.indices[3 * size_t(t)]);
        __builtin_prefetch(&alive_tri[t]);
        __builtin_prefetch(&s.sides[t]);
        if (witnessing) __builtin_prefetch(&witnesses[t]);
      }
    } else {
      for (uint32_t t : tris[v])
        for (int k = 0; k < 3; ++k)
          __builtin_prefetch(&pos[s.mesh.indices[3 * size_t(t) + size_t(k)]]);
    }
  }
  bool has(uint32_t t, uint32_t v) const {
    const uint32_t* i = &s.mesh.indices[3 * size_t(t)];
    return i[0] == v || i[1] == v || i[2] == v;
  }
  // Whether t is live and off the edge (u, v): a collapse of the edge keeps it.
  bool kept_by_collapse(uint32_t t, uint32_t u, uint32_t v) const {
    return alive_tri[t] && !(has(t, u) && has(t, v));
  }
  // The live triangles on edge (a, b).
  template <class F>
  void for_edge_triangles(uint32_t a, uint32_t b, F&& f) const {
    for (uint32_t t : tris[a])
      if (alive_tri[t] && has(t, b)) f(t);
  }
  // A junction edge: its triangles separate two or more different pairs of materials.
  bool junction_edge(uint32_t a, uint32_t b) const;
  // The neighbours of v over its live triangles that hold material m (all when m is ~0u),
  // sorted and unique.
  ListPool::Lease neighbours(uint32_t v, uint32_t m = ~0u) const;
  ListPool::Lease curve_neighbours(uint32_t v) const;
  double rho(uint32_t t) const;  // radii ratio

  // Witness checks, each leaving the new witnesses in `pending`. limit2: the squared bound
  // (infinity: any triangle will do, to keep every witness alive).
  // The collapse of u into v at `position` (u == v: the move of v to `position`). The check and
  // commit_witnesses touch the triangles around the two vertices and around their neighbours.
  bool collapse_keeps_witnesses(uint32_t u, uint32_t v, Vec3d position, double limit2);
  // The flip of t1 and t2 into `new1` and `new2` over the quad's `corners`.
  bool flip_keeps_witnesses(uint32_t t1, uint32_t t2, const std::array<uint32_t, 3>& new1,
                            const std::array<uint32_t, 3>& new2,
                            const std::array<uint32_t, 4>& corners, double limit2);
  void commit_witnesses();

  // Near where interfaces meet (the triangles within two rings of edge (u, v) are of more than
  // one interface), whether a triangle around the merged vertex at `position` would cross one
  // of those triangles: a sheet folded through another part's. Reads only the triangles around
  // u's and v's neighbours.
  bool crosses_nearby(uint32_t u, uint32_t v, const Vec3d& position) const;

  void prune(uint32_t v);  // dead triangles out of v's list
  // Writes the live triangles back into `s` (vertices renumbered, junction_vertices kept,
  // normals and colours cleared).
  void compact();

 private:
  template <class Shift, class FillFar>
  bool rewitness(std::span<const uint32_t> changed, double limit2, Shift&& shift,
                 FillFar&& fill_far);
  template <class Corner>
  void add_fan(uint32_t y, Corner&& corner, bool collapse, uint32_t u, uint32_t v,
               uint32_t skip1 = ~0u, uint32_t skip2 = ~0u);
  void add_to_fan(uint32_t t, const Vec3d& a, const Vec3d& b, const Vec3d& c);
  uint32_t witness_in_fan(const Vec3d& q, double limit2, double& distance) const;
};

}  // namespace segmesh
