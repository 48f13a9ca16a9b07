// Running the core from Python: the work on a thread of its own with the GIL released, while the
// calling thread, holding the GIL every 50 ms, checks for Ctrl-C (PyErr_CheckSignals: Python runs
// signal handlers on its main thread only) and calls the progress callback with the current step
// and fraction. A callback that returns False or raises, and KeyboardInterrupt, cancel the run
// through segmesh::Progress; the Python error is kept and raised once the core unwound.
// segmesh.mesh, mesh_file and run_case all run this way.
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "segmesh/progress.hpp"

namespace segmesh::python {

namespace py = pybind11;

// The core reports from any thread; Python is called only from the calling thread (poll, finish).
class PyProgress : public Progress {
 public:
  explicit PyProgress(py::object callback) : callback_(std::move(callback)) {}
  ~PyProgress() override;

  void step(std::string_view name) override;
  void update(double fraction) override { fraction_.store(fraction, std::memory_order_relaxed); }
  bool cancelled() const override { return cancelled_.load(std::memory_order_relaxed); }

  // On the calling thread, with the GIL held: Ctrl-C, then every step begun since the last poll
  // (fraction 0) and the current one with its fraction.
  void poll();
  // On the calling thread, with the GIL held, after a run that was not cancelled: the steps not
  // reported yet (a run shorter than one poll), then the last step at 1. The callback's error, if
  // it raises, is raised.
  void finish();
  // With the GIL held, after the core threw Cancelled: raises what cancelled the run, if it was
  // an error (the callback's or KeyboardInterrupt); returns false when the callback said stop.
  bool restore_error();

 private:
  void call(const std::string& step, double fraction);
  void cancel_with_python_error();
  // The steps begun since the last call, and the current one.
  std::vector<std::string> take_steps(std::string& current);

  py::object callback_;
  std::atomic<bool> cancelled_{false};
  std::atomic<double> fraction_{0};
  std::mutex step_mutex_;
  std::string step_;
  std::vector<std::string> begun_;  // steps begun since the last poll
  PyObject* error_type_ = nullptr;
  PyObject* error_value_ = nullptr;
  PyObject* error_trace_ = nullptr;
  std::exception_ptr other_error_;
};

// Runs `work` on a thread of its own (at most `threads` worker threads, 0: all cores), the GIL
// released, while this thread polls `progress`. Called with the GIL held. Raises the Python error
// that cancelled the run, or segmesh.Cancelled, or what `work` threw; a cancel that arrives after
// the core's last check is raised too (the run is complete, the interrupt is not swallowed).
// Calls progress.finish() after a complete run.
void run_polling(PyProgress& progress, int threads, const std::function<void()>& work);

}  // namespace segmesh::python
