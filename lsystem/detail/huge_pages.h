#pragma once
/// Transparent huge pages for large fresh buffers (module strings, skeletons).

#include <cstddef>
#include <cstdint>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace sprig::lsystem::detail {

/// Large fresh outputs are dominated by first-touch page faults (about half the time
/// for a 2-million-internode skeleton); asking Linux for transparent huge pages on the
/// buffer cuts the number of faults 512-fold. A hint only: failure changes nothing.
inline void adviseHugePages(void* data, size_t bytes) {
#ifdef __linux__
  constexpr uintptr_t kHuge = uintptr_t(2) << 20;
  if (bytes < 4 * kHuge) return;
  uintptr_t begin = (reinterpret_cast<uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
  uintptr_t end = (reinterpret_cast<uintptr_t>(data) + bytes) & ~(kHuge - 1);
  if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#else
  (void)data;
  (void)bytes;
#endif
}

/// Sizes v to n elements that the caller will overwrite: when v must grow, its old
/// contents are dropped rather than copied, and the new storage is advised huge pages
/// before anything touches it. Elements are value-initialized.
template <class T>
void resizeForOverwrite(std::vector<T>& v, size_t n) {
  if (n > v.capacity()) {
    v.clear();
    v.reserve(n);
    adviseHugePages(v.data(), v.capacity() * sizeof(T));
  }
  v.resize(n);
}

}  // namespace sprig::lsystem::detail
