#include "progress_bar.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace segmesh::cli {

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::step(std::string_view name) {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  step_ = std::string(name);
  draw(0);
}

void ProgressBar::update(double fraction) {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  if (fraction < 1 && now - last_draw_ < std::chrono::milliseconds(100)) return;
  draw(fraction);
}

void ProgressBar::draw(double fraction) {
  last_draw_ = std::chrono::steady_clock::now();
  constexpr int width = 30;
  const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * width);
  std::fprintf(stderr, "\r%-16s [%s%s] %3d%%", step_.c_str(), std::string(filled, '#').c_str(),
               std::string(width - filled, '.').c_str(), static_cast<int>(fraction * 100));
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressBar::finish() {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  if (drawn_) std::fprintf(stderr, "\r%60s\r", "");
  drawn_ = false;
}

}  // namespace segmesh::cli
