#pragma once
/// Parallel loops whose outputs join in a fixed order (the solids' determinism at any
/// thread count).

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/parallel.h"

namespace sprig::solids {

/// Items are processed in chunks of this many: chunk outputs are joined in chunk order, so
/// results never depend on the thread count.
constexpr size_t kChunk = 4096;

/// Runs f(begin, end, out) over fixed chunks of [0, n) in parallel and joins the outputs in order.
template <class T, class F>
std::vector<T> chunked(size_t n, F&& f) {
  const size_t chunks = (n + kChunk - 1) / kChunk;
  std::vector<std::vector<T>> parts(chunks);
  parallelFor(0, chunks, [&](size_t c) { f(c * kChunk, std::min(n, (c + 1) * kChunk), parts[c]); });
  std::vector<T> out;
  size_t total = 0;
  for (auto& p : parts) total += p.size();
  out.reserve(total);
  for (auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace sprig::solids
