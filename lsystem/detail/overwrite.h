#pragma once
/// Buffers rewritten from scratch (module strings).

#include <cstddef>
#include <vector>

namespace sprig::lsystem::detail {

/// Sizes v to n elements that the caller will overwrite: when v must grow, its old
/// contents are dropped rather than copied. Elements are value-initialized.
///
/// The new storage is left on small pages. It used to be advised transparent huge pages
/// (fewer first-touch faults), but on a virtual machine that hands freed memory back to
/// its host a fresh huge page costs the host's fault, about ten times a small page
/// (bench_fresh_pages), and `sprig derive grammars/abop_2_6.lsys --steps 22 --json` took
/// 2.98-3.39 s with the advice against 1.21-1.29 s without it (docs/PERFORMANCE.md,
/// "Fresh pages").
template <class T>
void resizeForOverwrite(std::vector<T>& v, size_t n) {
  if (n > v.capacity()) {
    v.clear();
    v.reserve(n);
  }
  v.resize(n);
}

}  // namespace sprig::lsystem::detail
