#pragma once
/// Wall-clock timing for reports and benchmarks.

#include <chrono>

namespace sprig {

/// Seconds of steady_clock time elapsed since t0.
inline double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace sprig
