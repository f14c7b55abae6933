#pragma once
/// Wall-clock and CPU timing for reports and benchmarks.

#include <chrono>
#include <ctime>

namespace sprig {

/// Seconds of steady_clock time elapsed since t0.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU seconds of the whole process (every thread): on idle cores, wall time is about this
/// divided by the number of busy threads.
inline double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace sprig
