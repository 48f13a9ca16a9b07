// A progress bar on stderr for the pipeline's steps, drawn only when stderr is a terminal.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

#include "segmesh/progress.hpp"

namespace segmesh::cli {

class ProgressBar : public Progress {
 public:
  explicit ProgressBar(bool enabled);
  ~ProgressBar() override;
  void step(std::string_view name) override;
  void update(double fraction) override;
  void finish();  // clears the bar's line

 private:
  void draw(double fraction);
  bool enabled_;
  std::mutex mutex_;
  std::string step_;
  std::chrono::steady_clock::time_point last_draw_{};
  bool drawn_ = false;
};

}  // namespace segmesh::cli
