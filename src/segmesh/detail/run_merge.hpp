// The N-way merge of sorted run lists: the intervals along x on which N rows of voxels, each a
// list of runs, keep one state. The extractors that read parts as runs per row use it
// (run_scan.hpp: one component, inside or outside; material_rows.hpp: every part at once, by
// material), so the walk over run ends is written once.
//
// A row is a list of runs [x_begin, x_end), x ascending and disjoint; runs may be adjacent (two
// parts touching); between runs the row is background. A row's state changes only at its run
// ends, so the merge visits each run end once: its cost is the number of run ends, never the
// length of the rows.
//
// What a row's state is belongs to the caller, as a plain struct with
//   bool inside(size_t n) const      row n is in a run
//   void enter(size_t n, const Run&) row n enters the run
//   void leave(size_t n)             row n leaves its run for the background
// RowBits keeps one bit per row, all rows' states in one word (the hot path of single-part
// Marching Cubes compares and switches on that word); RunValues keeps a value per row, taken from
// the run (a material).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

namespace segmesh {

// Bit n set while row n is in a run (N <= 32).
struct RowBits {
  unsigned bits = 0;
  bool inside(size_t n) const { return bits >> n & 1u; }
  template <class Run>
  void enter(size_t n, const Run&) {
    bits |= 1u << n;
  }
  void leave(size_t n) { bits &= ~(1u << n); }
};

namespace run_merge_detail {
template <class Member>
struct MemberType;
template <class Class, class Value>
struct MemberType<Value Class::*> {
  using type = Value;
};
}  // namespace run_merge_detail

// Row n's value is the member `Field` of its run, Value{} on the background (so no run may have
// the value Value{}).
template <size_t N, auto Field>
struct RunValues {
  using Value = typename run_merge_detail::MemberType<decltype(Field)>::type;
  std::array<Value, N> value{};
  bool inside(size_t n) const { return value[n] != Value{}; }
  template <class Run>
  void enter(size_t n, const Run& run) {
    value[n] = run.*Field;
  }
  void leave(size_t n) { value[n] = Value{}; }
};

// Calls visit(s, t, state) for consecutive intervals [s, t) covering [0, nx), s ascending, on
// which the state of the N rows is constant; a new interval starts wherever a run of a row begins
// or ends (so two intervals in a row have equal states only where a row's adjacent runs do). A
// run's local x is its x_begin (x_end) minus x0. `state` starts as State{}: every row outside.
// Always inlined: it is the inner loop of the extractors' counting and filling, whose visits are a
// few instructions, and compiled into each caller the compiler can fold the visit and the state
// into the loop (out of line, RunScan's counting ran more instructions than its own merge did).
template <class State, size_t N, class Run, class Visit>
[[gnu::always_inline]] inline void merge_runs(int64_t nx, int64_t x0, const std::array<std::span<const Run>, N>& rows,
                Visit&& visit) {
  State state{};
  std::array<size_t, N> at{};     // row n's current run, or its next one when outside
  std::array<int64_t, N> next{};  // where row n's state changes next
  for (size_t n = 0; n < N; ++n) next[n] = rows[n].empty() ? nx : rows[n][0].x_begin - x0;
  int64_t s = 0;
  while (s < nx) {
    int64_t t = nx;
    for (size_t n = 0; n < N; ++n) t = next[n] < t ? next[n] : t;
    if (t > s) visit(s, t, static_cast<const State&>(state));
    if (t >= nx) break;
    for (size_t n = 0; n < N; ++n) {
      if (next[n] != t) continue;
      const auto& runs = rows[n];
      if (state.inside(n)) {  // the run ends at t
        state.leave(n);
        ++at[n];
        next[n] = at[n] < runs.size() ? runs[at[n]].x_begin - x0 : nx;
        if (next[n] != t) continue;  // else the next run begins where this one ends (t < nx)
      }
      state.enter(n, runs[at[n]]);  // a run begins at t
      next[n] = runs[at[n]].x_end - x0;
    }
    s = t;
  }
}

}  // namespace segmesh
