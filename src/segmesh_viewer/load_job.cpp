#include "segmesh_viewer/load_job.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <new>

#include "segmesh/error.hpp"

namespace segmesh::viewer {

struct LoadJob::Shared {
  mutable std::mutex mutex;
  std::condition_variable finished_cv;
  bool running = false;
  std::string step;
  std::atomic<double> fraction{0};
  std::atomic<bool> cancel{false};
  std::optional<LoadOutcome> outcome;
};

namespace {

class JobProgress final : public Progress {
 public:
  explicit JobProgress(LoadJob::Shared& shared) : shared_(shared) {}
  void step(std::string_view name) override {
    std::lock_guard lock(shared_.mutex);
    shared_.step = std::string(name);
    shared_.fraction = 0;
  }
  void update(double fraction) override { shared_.fraction = fraction; }
  bool cancelled() const override { return shared_.cancel.load(); }

 private:
  LoadJob::Shared& shared_;
};

std::string describe(const LoadResult& r, double seconds) {
  int64_t triangles = 0;
  for (const PartStats& s : r.stats) triangles += s.triangles;
  char time[32];
  std::snprintf(time, sizeof time, " in %.1f s", seconds);
  return r.source + ": " + std::to_string(r.scene.parts.size()) + " parts, " +
         std::to_string(triangles) + " triangles, " + (r.kind == InputKind::volume ? "meshed" : "read") +
         time;
}

LoadOutcome run(const LoadRequest& request, LoadJob::Shared& shared) {
  JobProgress progress(shared);
  const std::string what = request.image ? request.image->path : request.path.string();
  try {
    const auto start = std::chrono::steady_clock::now();
    LoadResult result = run_load(request, progress);
    std::string message =
        describe(result, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    return {LoadOutcome::Kind::loaded, std::move(result), std::move(message)};
  } catch (const Cancelled&) {
    return {LoadOutcome::Kind::cancelled, std::nullopt, "cancelled; the scene is unchanged"};
  } catch (const Error& e) {
    return {LoadOutcome::Kind::failed, std::nullopt, e.what()};
  } catch (const std::bad_alloc&) {
    return {LoadOutcome::Kind::failed, std::nullopt, what + ": not enough memory to open it"};
  } catch (const std::exception& e) {
    return {LoadOutcome::Kind::failed, std::nullopt, what + ": internal error: " + e.what()};
  } catch (...) {
    return {LoadOutcome::Kind::failed, std::nullopt, what + ": internal error"};
  }
}

}  // namespace

LoadJob::LoadJob() : shared_(std::make_shared<Shared>()) {}

LoadJob::~LoadJob() {
  cancel();
  if (thread_.joinable()) thread_.join();
}

bool LoadJob::start(LoadRequest request) {
  {
    std::lock_guard lock(shared_->mutex);
    if (shared_->running || shared_->outcome) return false;
    shared_->running = true;
    shared_->step = "starting";
    shared_->fraction = 0;
    shared_->cancel = false;
  }
  if (thread_.joinable()) thread_.join();
  thread_ = std::jthread([shared = shared_, request = std::move(request)] {
    LoadOutcome outcome = run(request, *shared);
    std::lock_guard lock(shared->mutex);
    shared->outcome = std::move(outcome);
    shared->running = false;
    shared->finished_cv.notify_all();
  });
  return true;
}

void LoadJob::cancel() { shared_->cancel = true; }

JobStatus LoadJob::status() const {
  std::lock_guard lock(shared_->mutex);
  return {shared_->running, shared_->step, shared_->fraction.load()};
}

std::optional<LoadOutcome> LoadJob::take_outcome() {
  std::lock_guard lock(shared_->mutex);
  std::optional<LoadOutcome> outcome = std::move(shared_->outcome);
  shared_->outcome.reset();
  return outcome;
}

void LoadJob::wait() {
  std::unique_lock lock(shared_->mutex);
  shared_->finished_cv.wait(lock, [&] { return !shared_->running; });
}

void finish_load(ViewerState& state, LoadOutcome outcome) {
  if (outcome.kind == LoadOutcome::Kind::loaded && outcome.result) {
    LoadResult& r = *outcome.result;
    set_scene(state, std::move(r.scene), std::move(r.stats), std::move(r.source), std::move(r.image));
    state.surfaces = std::move(r.surfaces);
    set_message(state, std::move(outcome.message));
  } else {
    set_message(state, std::move(outcome.message), outcome.kind == LoadOutcome::Kind::failed);
  }
}

}  // namespace segmesh::viewer
