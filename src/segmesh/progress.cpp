#include "segmesh/progress.hpp"

#include <algorithm>

#include "segmesh/error.hpp"

namespace segmesh {

Progress& null_progress() {
  static Progress none;
  return none;
}

void throw_if_cancelled(const Progress& progress) {
  if (progress.cancelled()) throw Cancelled();
}

class PartsProgress::Piece : public Progress {
 public:
  Piece(PartsProgress& owner, size_t index) : owner_(owner), index_(index) {}
  void update(double fraction) override { owner_.advance(index_, fraction); }
  bool cancelled() const override { return owner_.step_.cancelled(); }

 private:
  PartsProgress& owner_;
  size_t index_;
};

PartsProgress::PartsProgress(Progress& step, const std::vector<double>& weights)
    : step_(step), weights_(weights), fractions_(new std::atomic<double>[weights.size()]) {
  for (size_t i = 0; i < weights_.size(); ++i) {
    total_weight_ += weights_[i];
    fractions_[i] = 0;
    pieces_.push_back(std::make_unique<Piece>(*this, i));
  }
}

PartsProgress::~PartsProgress() = default;

Progress& PartsProgress::part(size_t i) {
  return *pieces_[i];
}

void PartsProgress::done(size_t i) {
  advance(i, 1.0);
}

void PartsProgress::advance(size_t i, double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  double before = fractions_[i].load(std::memory_order_relaxed);
  while (fraction > before && !fractions_[i].compare_exchange_weak(before, fraction)) {
  }
  if (fraction <= before) return;  // not further than this piece has been
  const double sum =
      sum_.fetch_add((fraction - before) * weights_[i]) + (fraction - before) * weights_[i];
  step_.update(total_weight_ > 0 ? std::min(1.0, sum / total_weight_) : 1.0);
}

}  // namespace segmesh
