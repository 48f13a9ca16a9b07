// LoadJob: run_load (load_input.hpp) on a worker thread, so the window stays responsive while a
// volume is read and meshed. The window polls status() every frame for the progress bar, calls
// cancel() for the Cancel button and take_outcome() to collect the result; finish_load applies an
// outcome to the ViewerState. A failure never reaches the window as an exception: bad input
// (segmesh::Error), cancellation and internal faults become an Outcome with a message, and the
// current scene is kept.
//
// Cancellation goes through segmesh::Progress::cancelled(), which the pipeline checks once per
// block of work; cancel() returns at once and the worker stops at its next check (reading a
// volume is not interruptible, so a cancel during "reading" takes effect after the read).
// The destructor cancels and joins. One job at a time: start() while running is refused.
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "segmesh_viewer/load_input.hpp"
#include "segmesh_viewer/viewer_state.hpp"

namespace segmesh::viewer {

struct JobStatus {
  bool running = false;
  std::string step;       // "reading", the pipeline's step names, "measuring"
  double fraction = 0;    // of the current step, 0..1
};

struct LoadOutcome {
  enum class Kind { loaded, failed, cancelled } kind = Kind::failed;
  std::optional<LoadResult> result;  // set when loaded
  std::string message;               // one line: what was loaded, or what went wrong
};

class LoadJob {
 public:
  LoadJob();
  ~LoadJob();
  LoadJob(const LoadJob&) = delete;
  LoadJob& operator=(const LoadJob&) = delete;

  // Starts the job; false (and nothing started) when one is still running or its outcome has not
  // been taken.
  bool start(LoadRequest request);
  void cancel();
  JobStatus status() const;
  // The finished job's outcome, once; nullopt while running or when there is none.
  std::optional<LoadOutcome> take_outcome();
  // Blocks until the job has finished (for --screenshot and tests).
  void wait();

  struct Shared;  // the state the worker and the window share (load_job.cpp)

 private:
  std::shared_ptr<Shared> shared_;
  std::jthread thread_;
};

// Applies an outcome: a loaded result replaces the scene (set_scene) and its surfaces line; a
// failure or cancellation keeps both. Either way the status message is set (an error for a failure).
void finish_load(ViewerState& state, LoadOutcome outcome);

}  // namespace segmesh::viewer
