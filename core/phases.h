#pragma once
/// Where a command's wall time went: a process-wide clock that charges elapsed time to named
/// phases ("read", "derive", "build", "cells", "scene", "render", "write", ...).
///
/// Representation: one stack of open phases on the thread that started the clock (the
/// command's thread). Time is always charged to the innermost open phase, so phases are
/// exclusive: a "derive" opened inside "build" pauses "build". Time outside every phase is
/// "other", and the time from the process's start (the kernel's start time of the process)
/// to PhaseClock::start() is "start-up"; so the phases add up to the total by construction,
/// and "other" says how much no phase accounts for. Phase scopes opened on any other thread
/// (a parallel loop's workers, the gallery's species) do nothing: the phases stay
/// sequential and the same at any thread count. Cost: one clock read per scope.

#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

namespace sprig {

/// The process-wide phase clock (see the file comment).
class PhaseClock {
 public:
  /// Starts the clock on the calling thread (again: restarts it, dropping what was charged).
  static void start();
  /// Lists these phases in this order (at 0 s until used), so a command's summary always
  /// names them; call after start(), on its thread.
  static void declare(std::initializer_list<const char*> names);
  /// Phases in order of first use with their seconds, "start-up" first and "other" last
  /// (both always present); their sum is total(). Empty before start().
  static std::vector<std::pair<std::string, double>> phases();
  /// Seconds since the process started (0 before start()).
  static double total();
  /// "read 0.01 s, derive 0.20 s, ..., other 0.00 s; 1.25 s wall" (phases() in one line).
  static std::string summary();
  /// {"command":"render","total":1.25,"phases":{"start-up":0.01,"read":0.01,...}} on one line.
  static std::string json(const std::string& command);
};

/// Charges the time until it is destroyed to phase `name` (a string literal), on the
/// clock's thread; elsewhere it does nothing.
class Phase {
 public:
  explicit Phase(const char* name);
  ~Phase();
  Phase(const Phase&) = delete;
  Phase& operator=(const Phase&) = delete;

 private:
  bool active_ = false;
};

}  // namespace sprig
