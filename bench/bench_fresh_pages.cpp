/// What a page of memory costs the first time a process touches it, against a page it has
/// just freed and touches again (the baseline, in the same run).
///
/// Usage: bench_fresh_pages [--mb N] (default 256)
///
/// On a virtual machine whose host backs the guest's memory only when first touched, and
/// takes freed memory back (free page reporting), the first touch of a fresh page costs the
/// host's fault and zeroing; a page the process freed a moment ago is still backed. Sprig's
/// large working arrays (the polygonizer's grid, the mesh's arrays) pay the first cost once
/// per page; blobtree/polygonize.cpp releases arrays early so later ones reuse their pages.
/// Prints MB/s of both touches and their ratio; run it a few seconds after any large
/// process has exited (freed memory is reported to the host about two seconds after).

#include "bench/bench_clock.h"

#include <sys/mman.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

using namespace sprig::bench;

namespace {

constexpr size_t kHuge = size_t(2) << 20;

/// Allocates mb MB (huge-page aligned, marked for huge pages as the polygonizer's arrays
/// are), writes one byte a 4 KB page, and returns the seconds taken; frees it.
double touch(size_t mb) {
  const size_t bytes = mb << 20;
  const auto t0 = Clock::now();
  auto* p = static_cast<volatile char*>(std::aligned_alloc(kHuge, bytes));
  if (!p) {
    std::fprintf(stderr, "bench_fresh_pages: cannot allocate %zu MB\n", mb);
    std::exit(1);
  }
  madvise(const_cast<char*>(p), bytes, MADV_HUGEPAGE);
  for (size_t i = 0; i < bytes; i += 4096) p[i] = 1;
  const double s = seconds(t0);
  std::free(const_cast<char*>(p));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  size_t mb = 256;
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--mb") && i + 1 < argc) mb = size_t(std::atol(argv[++i]));
  if (mb == 0) return 1;
  const double fresh = touch(mb), again = touch(mb);
  std::printf("%zu MB: first touch %.3f s (%.0f MB/s), touched again after free %.3f s (%.0f MB/s); "
              "fresh / reused = %.1fx\n",
              mb, fresh, double(mb) / fresh, again, double(mb) / again, fresh / again);
  return 0;
}
