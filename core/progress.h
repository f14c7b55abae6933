#pragma once
/// Progress reporting for long operations, and cooperative cancellation.
///
/// On a terminal (stderr is a tty) a bar with percentage, rate and ETA is redrawn at
/// most ten times a second; otherwise, or when quiet, nothing is printed. advance() is
/// thread-safe and cheap (one relaxed atomic add; the redraw is throttled).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace sprig {

/// Told of every Progress's state, for a program that embeds Sprig and shows progress its
/// own way (the Python module, python/). Called from whichever thread advances a bar, at
/// most ten times a second per bar and once when it finishes, so update() must be cheap and
/// thread-safe; it may call ProgressSettings::requestCancel().
class ProgressObserver {
 public:
  virtual ~ProgressObserver() = default;
  /// label: the bar's label; done of total units (total 0 = unknown).
  virtual void update(const std::string& label, uint64_t done, uint64_t total) = 0;
};

/// Process-wide switches for progress output and cancellation.
struct ProgressSettings {
  /// Silences every bar (the CLI's --quiet).
  static void setQuiet(bool quiet);
  /// True after setQuiet(true).
  static bool quiet();
  /// Asks long operations to stop at their next check (set from a signal handler too).
  static void requestCancel();
  /// True once requestCancel() was called.
  static bool cancelRequested();
  /// Withdraws a cancellation request, so that a program that goes on after a cancelled
  /// operation (the Python module after KeyboardInterrupt) can start the next one.
  static void clearCancel();
  /// Sets the one observer told of every bar's progress (null = none). Process-wide like
  /// the switches above (an embedding program has one); the observer must outlive the bars
  /// created while it is set.
  static void setObserver(ProgressObserver* observer);
};

/// Thrown by long operations that noticed a cancellation request.
struct Cancelled : std::exception {
  /// "cancelled".
  const char* what() const noexcept override { return "cancelled"; }
};

/// One progress bar over `total` units of work.
class Progress {
 public:
  /// label: shown before the bar; total: units of work (0 = unknown).
  Progress(std::string label, uint64_t total);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Adds n finished units; redraws when due. Throws Cancelled if cancellation was requested.
  void advance(uint64_t n = 1);
  /// Draws the final state and ends the line.
  void finish();
  /// Seconds since construction.
  double elapsed() const;

 private:
  void draw(bool final);

  std::string label_;
  uint64_t total_;
  std::atomic<uint64_t> done_{0};
  std::atomic<int64_t> nextDrawNs_{0};
  std::chrono::steady_clock::time_point start_;
  std::mutex drawMutex_;
  bool enabled_;
  ProgressObserver* observer_;  ///< ProgressSettings' observer when the bar was made
  bool finished_ = false;
};

}  // namespace sprig
