// Progress: how long-running steps report how far they are and learn that they should stop.
//
// Modelled on OpenVDB's interrupter: algorithms call step() when a named step begins, update() now
// and then (at most once per block of work, from any thread), and check cancelled() at the same
// rate, throwing segmesh::Cancelled when it turns true. Implementations must be thread-safe.
// The CLI draws a bar on stderr, the viewer a widget, tests can cancel.
#pragma once

#include <string_view>

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

}  // namespace segmesh
