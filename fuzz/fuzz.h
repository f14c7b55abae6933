#pragma once
/// The libFuzzer entry point every fuzz target defines, and what the targets share.
/// Built with clang -fsanitize=fuzzer into build-asan/fuzz_<target> (`make fuzz`), and with
/// the normal compiler into fuzz_replay_<target> (fuzz/replay_main.cpp), which feeds the
/// files of fuzz/regressions/<target>/ to the same function under ctest.

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace sprig::fuzz {

/// The input as text (any bytes: the readers must refuse what is not text themselves).
inline std::string_view text(const uint8_t* data, size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Inputs larger than this are skipped: the readers' size limits are tested elsewhere
/// (tests/bad_inputs), and large inputs only slow the search.
inline constexpr size_t kMaxInput = 64 * 1024;

}  // namespace sprig::fuzz
