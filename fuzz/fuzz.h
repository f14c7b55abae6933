#pragma once
/// The libFuzzer entry point every fuzz target defines, and what the targets share.
/// Built with clang -fsanitize=fuzzer into build-asan/fuzz_<target> (`make fuzz`), and with
/// the normal compiler into fuzz_replay_<target> (fuzz/replay_main.cpp), which feeds the
/// files of fuzz/regressions/<target>/ to the same function under ctest.

#include <stdlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
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

namespace detail {
inline std::string& sandboxPath() {
  static std::string path;
  return path;
}
inline void removeSandbox() {
  std::error_code ec;
  if (!sandboxPath().empty()) std::filesystem::remove_all(sandboxPath(), ec);
}
}  // namespace detail

/// The process's private folder `/tmp/sprig-fuzz-NAME-XXXXXX`, made on the first call (the
/// replay build calls no initializer; made, when given, then puts its files in it) and
/// removed at exit; when it cannot be made, a folder that does not exist, so that every
/// name in it is missing.
inline const std::string& sandboxFolder(const char* name, void (*made)(const std::string&) = nullptr) {
  std::string& path = detail::sandboxPath();
  if (path.empty()) {
    std::string pattern = std::string("/tmp/sprig-fuzz-") + name + "-XXXXXX";
    if (const char* dir = ::mkdtemp(pattern.data())) {
      path = dir;
      if (made) made(path);
      std::atexit(detail::removeSandbox);
    } else {
      path = "/sprig-fuzz-sandbox";
    }
  }
  return path;
}

}  // namespace sprig::fuzz
