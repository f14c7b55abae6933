#pragma once
/// Running a long Sprig operation from Python: the GIL released, progress reported to a
/// Python callback, and Ctrl-C (KeyboardInterrupt) stopping it through Sprig's own
/// cancellation (core/progress.h).
///
/// The work runs on a worker thread while the calling thread, the one Python delivers
/// signals to, wakes every 50 ms with the GIL re-acquired: it runs the signal handlers
/// (PyErr_CheckSignals) and hands the latest progress (a ProgressObserver that Progress
/// bars report to) to the callback. A pending KeyboardInterrupt, or an exception raised by
/// the callback, requests cancellation; the operation stops at its next progress check
/// (throwing Cancelled), and the Python exception is raised in its place. One operation runs
/// at a time in the process (the observer and the cancellation flag are process-wide).

#include <pybind11/pybind11.h>

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <utility>

#include "core/progress.h"

namespace sprig::python {

/// The latest state any progress bar reported, for the calling thread to pick up.
class CallProgress final : public ProgressObserver {
 public:
  void update(const std::string& label, uint64_t done, uint64_t total) override {
    std::lock_guard<std::mutex> lock(mutex_);
    label_ = label;
    done_ = done;
    total_ = total;
    fresh_ = true;
  }
  /// The state reported since the last take, or false when there is none.
  bool take(std::string& label, uint64_t& done, uint64_t& total) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!fresh_) return false;
    label = label_;
    done = done_;
    total = total_;
    fresh_ = false;
    return true;
  }

 private:
  std::mutex mutex_;
  std::string label_;
  uint64_t done_ = 0, total_ = 0;
  bool fresh_ = false;
};

/// The mutex that lets one long operation run at a time.
inline std::mutex& callMutex() {
  static std::mutex m;
  return m;
}

/// Calls progress(label, done, total) with the latest state, if any and progress is not
/// None; returns false (the Python error kept in pyError) when the callback raised.
inline bool reportProgress(CallProgress& observer, const pybind11::object& progress,
                           std::optional<pybind11::error_already_set>& pyError) {
  std::string label;
  uint64_t done = 0, total = 0;
  if (progress.is_none() || !observer.take(label, done, total)) return true;
  try {
    progress(label, done, total);
  } catch (pybind11::error_already_set& e) {
    pyError.emplace(std::move(e));
    return false;
  }
  return true;
}

/// Runs work() (pure C++: it must not touch Python objects) with the GIL released, as the
/// file comment says, and returns its result. Called with the GIL held. Throws what work
/// throws, or the Python exception (KeyboardInterrupt, the callback's) that cancelled it.
template <class F>
auto runLong(F&& work, const pybind11::object& progress) -> std::invoke_result_t<F&> {
  namespace py = pybind11;
  using Result = std::invoke_result_t<F&>;
  std::unique_lock<std::mutex> exclusive(callMutex(), std::defer_lock);
  {
    py::gil_scoped_release nogil;
    exclusive.lock();
  }
  CallProgress observer;
  ProgressSettings::clearCancel();
  ProgressSettings::setObserver(&observer);
  std::optional<Result> result;
  std::exception_ptr error;
  std::mutex doneMutex;
  std::condition_variable doneSignal;
  bool finished = false;
  std::thread worker([&] {
    try {
      result.emplace(work());
    } catch (...) {
      error = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(doneMutex);
    finished = true;
    doneSignal.notify_one();
  });
  std::optional<py::error_already_set> pyError;
  for (;;) {
    bool over = false;
    {
      py::gil_scoped_release nogil;
      std::unique_lock<std::mutex> lock(doneMutex);
      over = doneSignal.wait_for(lock, std::chrono::milliseconds(50), [&] { return finished; });
    }
    if (over) break;
    if (pyError) continue;  // cancelled already; waiting for the work to notice
    if (PyErr_CheckSignals() != 0) {
      pyError.emplace();  // fetches the pending exception (KeyboardInterrupt)
      ProgressSettings::requestCancel();
    } else if (!reportProgress(observer, progress, pyError)) {
      ProgressSettings::requestCancel();
    }
  }
  {
    py::gil_scoped_release nogil;
    worker.join();
  }
  ProgressSettings::setObserver(nullptr);
  ProgressSettings::clearCancel();
  if (pyError) throw std::move(*pyError);
  if (error) std::rethrow_exception(error);
  if (!reportProgress(observer, progress, pyError)) throw std::move(*pyError);
  return std::move(*result);
}

}  // namespace sprig::python
