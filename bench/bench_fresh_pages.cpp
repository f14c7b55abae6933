/// What a page of memory costs the first time a process touches it: fresh small (4 KB)
/// pages, fresh transparent huge (2 MB) pages, and, as the baseline in the same run, a
/// block the process has just freed and touches again.
///
/// Usage: bench_fresh_pages [--mb N] (default 256)
///
/// On a virtual machine whose host backs the guest's memory only when first touched, and
/// takes freed memory back (free page reporting), the first touch of a fresh page costs the
/// host's fault; a huge page needs a whole free 2 MB block, the kind the guest has handed
/// back, so it costs the most. Sprig's polygonizer keeps its large arrays on small pages
/// and releases arrays early so later ones reuse their pages (blobtree/polygonize.cpp).
/// Prints the seconds and MB/s of each touch and their ratios to the reused block; run it
/// a few seconds after any large process has exited (freed memory is reported to the host
/// about two seconds after).

#include "bench/bench_clock.h"

#include <sys/mman.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

using namespace sprig::bench;

namespace {

constexpr size_t kHuge = size_t(2) << 20;

/// Allocates mb MB (2 MB aligned), advises huge or small pages, writes one byte a 4 KB page
/// and returns the seconds taken; the block is freed only when keep is null.
double touch(size_t mb, int advice, volatile char** keep = nullptr) {
  const size_t bytes = mb << 20;
  const auto t0 = Clock::now();
  auto* p = static_cast<volatile char*>(std::aligned_alloc(kHuge, bytes));
  if (!p) {
    std::fprintf(stderr, "bench_fresh_pages: cannot allocate %zu MB\n", mb);
    std::exit(1);
  }
  madvise(const_cast<char*>(p), bytes, advice);
  for (size_t i = 0; i < bytes; i += 4096) p[i] = 1;
  const double s = seconds(t0);
  if (keep) *keep = p;
  else std::free(const_cast<char*>(p));
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  size_t mb = 256;
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--mb") && i + 1 < argc) mb = size_t(std::atol(argv[++i]));
  if (mb == 0) {
    std::fprintf(stderr, "bench_fresh_pages: --mb needs a positive number of megabytes\n");
    return 1;
  }
  // Both fresh blocks are kept while the other is touched, so neither reuses the other's pages.
  volatile char *small = nullptr, *huge = nullptr;
  const double freshSmall = touch(mb, MADV_NOHUGEPAGE, &small);
  const double freshHuge = touch(mb, MADV_HUGEPAGE, &huge);
  std::free(const_cast<char*>(small));
  std::free(const_cast<char*>(huge));
  const double reused = touch(mb, MADV_NOHUGEPAGE);
  std::printf("%zu MB: fresh small pages %.3f s (%.0f MB/s), fresh huge pages %.3f s (%.0f MB/s), "
              "reused after free %.3f s (%.0f MB/s); fresh small / reused = %.1fx, fresh huge / reused = %.1fx\n",
              mb, freshSmall, double(mb) / freshSmall, freshHuge, double(mb) / freshHuge, reused, double(mb) / reused,
              freshSmall / reused, freshHuge / reused);
  return 0;
}
