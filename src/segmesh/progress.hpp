// Progress: how long-running steps report how far they are and learn that they should stop.
//
// Modelled on OpenVDB's interrupter: algorithms call step() when a named step begins, update() now
// and then (at most once per block of work, from any thread), and check cancelled() at the same
// rate, throwing segmesh::Cancelled when it turns true. Implementations must be thread-safe.
// The CLI draws a bar on stderr, the viewer a widget, tests can cancel.
//
// Two adapters let one step's progress come from inside the work it is made of: SubProgress maps
// an algorithm's own 0..1 onto a stretch of the step (Gaussian filtering, then extraction), and
// PartsProgress shares a step between parts extracted in parallel, each weighted by its size, so
// one large part moves the bar while it is extracted and a cancel reaches inside it.
#pragma once

#include <atomic>
#include <memory>
#include <string_view>
#include <vector>

namespace segmesh {

class Progress {
 public:
  virtual ~Progress() = default;
  virtual void step(std::string_view /*name*/) {}
  virtual void update(double /*fraction_of_step*/) {}
  virtual bool cancelled() const { return false; }
};

// A Progress that shows nothing and never cancels.
Progress& null_progress();

// Throws Cancelled when progress.cancelled().
void throw_if_cancelled(const Progress& progress);

// update(f) reports from + f * (to - from) to `parent`; step names are not passed on (the caller
// names the step); cancelled() is the parent's.
class SubProgress : public Progress {
 public:
  SubProgress(Progress& parent, double from, double to) : parent_(parent), from_(from), to_(to) {}
  void update(double fraction) override { parent_.update(from_ + fraction * (to_ - from_)); }
  bool cancelled() const override { return parent_.cancelled(); }

 private:
  Progress& parent_;
  double from_, to_;
};

// One step shared by pieces of work that run side by side, piece i weighing weights[i]: part(i)
// is piece i's own Progress (its fraction 0..1; step names ignored; cancelled() is the step's),
// and the step is updated with the weighted mean of the pieces' fractions, each piece counting
// its largest fraction so far (updates from several threads may arrive out of order). done(i)
// counts piece i as complete. Thread-safe; the object must outlive the work.
class PartsProgress {
 public:
  PartsProgress(Progress& step, const std::vector<double>& weights);
  ~PartsProgress();
  Progress& part(size_t i);
  void done(size_t i);

 private:
  class Piece;
  void advance(size_t i, double fraction);

  Progress& step_;
  double total_weight_ = 0;
  std::vector<double> weights_;
  std::unique_ptr<std::atomic<double>[]> fractions_;  // each piece's largest fraction so far
  std::atomic<double> sum_{0};                        // sum of weight * fraction
  std::vector<std::unique_ptr<Piece>> pieces_;
};

}  // namespace segmesh
