#include "python_progress.hpp"

#include <tbb/global_control.h>

#include <chrono>
#include <condition_variable>
#include <memory>
#include <thread>

#include "segmesh/error.hpp"

namespace segmesh::python {

PyProgress::~PyProgress() {
  Py_XDECREF(error_type_);
  Py_XDECREF(error_value_);
  Py_XDECREF(error_trace_);
}

void PyProgress::step(std::string_view name) {
  std::lock_guard lock(step_mutex_);
  step_ = name;
  begun_.push_back(step_);
  fraction_.store(0, std::memory_order_relaxed);
}

std::vector<std::string> PyProgress::take_steps(std::string& current) {
  std::vector<std::string> begun;
  std::lock_guard lock(step_mutex_);
  begun.swap(begun_);
  current = step_;
  return begun;
}

void PyProgress::poll() {
  if (cancelled_.load()) return;
  if (PyErr_CheckSignals() != 0) return cancel_with_python_error();
  if (callback_.is_none()) return;
  // Every step is reported, with fraction 0, also one that began and ended since the last poll;
  // then the current step with its fraction.
  std::string step;
  const std::vector<std::string> begun = take_steps(step);
  if (step.empty()) return;
  try {
    for (size_t i = 0; i + 1 < begun.size() && !cancelled_.load(); ++i) call(begun[i], 0);
    if (!cancelled_.load()) call(step, fraction_.load(std::memory_order_relaxed));
  } catch (py::error_already_set& e) {
    e.restore();
    cancel_with_python_error();
  } catch (...) {  // nothing may leave the polling loop while the run goes on
    other_error_ = std::current_exception();
    cancelled_.store(true);
  }
}

void PyProgress::finish() {
  if (callback_.is_none() || cancelled_.load()) return;
  std::string step;
  const std::vector<std::string> begun = take_steps(step);
  for (size_t i = 0; i + 1 < begun.size(); ++i) call(begun[i], 0);
  if (!step.empty()) call(step, 1);
}

bool PyProgress::restore_error() {
  if (other_error_) std::rethrow_exception(other_error_);
  if (!error_type_) return false;
  PyErr_Restore(error_type_, error_value_, error_trace_);
  error_type_ = error_value_ = error_trace_ = nullptr;
  return true;
}

void PyProgress::call(const std::string& step, double fraction) {
  const py::object result = callback_(step, fraction);
  if (result.is_none()) return;
  const int truth = PyObject_IsTrue(result.ptr());
  if (truth < 0) throw py::error_already_set();
  if (truth == 0) cancelled_.store(true);
}

void PyProgress::cancel_with_python_error() {
  PyErr_Fetch(&error_type_, &error_value_, &error_trace_);
  cancelled_.store(true);
}

void run_polling(PyProgress& progress, int threads, const std::function<void()>& work) {
  std::exception_ptr error;
  {
    py::gil_scoped_release release;
    std::mutex mutex;
    std::condition_variable finished;
    bool done = false;
    std::thread worker([&] {
      try {
        std::unique_ptr<tbb::global_control> limit;
        if (threads > 0) {
          limit = std::make_unique<tbb::global_control>(
              tbb::global_control::max_allowed_parallelism, size_t(threads));
        }
        work();
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard lock(mutex);
      done = true;
      finished.notify_one();
    });
    std::unique_lock lock(mutex);
    while (!finished.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) {
      lock.unlock();
      {
        py::gil_scoped_acquire gil;
        progress.poll();
      }
      lock.lock();
    }
    lock.unlock();
    worker.join();
  }
  if (error) {
    try {
      std::rethrow_exception(error);
    } catch (const Cancelled&) {
      if (progress.restore_error()) throw py::error_already_set();
      throw;
    }
  }
  // Cancelled after the core's last check (Ctrl-C during the last moments): the run is complete,
  // but the interrupt is not swallowed, and a callback's stop is honoured the same way.
  if (progress.cancelled()) {
    if (progress.restore_error()) throw py::error_already_set();
    throw Cancelled();
  }
  progress.finish();
}

}  // namespace segmesh::python
