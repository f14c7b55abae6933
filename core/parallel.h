#pragma once
/// Parallel loops on TBB and the process-wide thread limit.
///
/// Work is split into index ranges; callers must make each index's result independent
/// of which thread runs it (derive random seeds from the index, write to index-owned
/// slots), which keeps output identical at any thread count.

#include <cstddef>
#include <memory>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace sprig {

/// Limits every parallel loop to `threads` threads while alive (0 = all cores).
class ThreadLimit {
 public:
  /// Limits parallel loops to threads (0 = all cores) until destroyed.
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Number of threads parallel loops may use now.
int threadCount();

/// Calls f(i) for every i in [begin, end), in parallel, `grain` indices at a time at least.
template <class F>
void parallelFor(size_t begin, size_t end, F&& f, size_t grain = 1) {
  if (end <= begin) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, grain), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

/// Calls f(rangeBegin, rangeEnd) on disjoint chunks covering [begin, end).
template <class F>
void parallelForRange(size_t begin, size_t end, F&& f, size_t grain = 1) {
  if (end <= begin) return;
  tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, grain),
                    [&](const tbb::blocked_range<size_t>& r) { f(r.begin(), r.end()); });
}

}  // namespace sprig
