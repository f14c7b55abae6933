#pragma once
/// Clocks for the benchmarks: wall time, and CPU time, which is the steadier measure on a
/// shared, loaded machine (it does not count the time a thread waits for a core).

#include <sys/resource.h>

#include <chrono>
#include <ctime>

#include "core/timer.h"

namespace sprig::bench {

using Clock = std::chrono::steady_clock;

/// Wall seconds since start.
inline double seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

namespace detail {
inline double cpuSeconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
}  // namespace detail

/// CPU seconds of the whole process (all threads): core/timer.h's.
using sprig::processCpuSeconds;

/// CPU seconds of the calling thread.
inline double threadCpuSeconds() { return detail::cpuSeconds(CLOCK_THREAD_CPUTIME_ID); }

/// Peak resident memory in MB of this process (RUSAGE_SELF) or of its waited-for children
/// (RUSAGE_CHILDREN).
inline double peakMB(int who = RUSAGE_SELF) {
  rusage u{};
  getrusage(who, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

}  // namespace sprig::bench
