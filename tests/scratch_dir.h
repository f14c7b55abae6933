#pragma once
/// Scratch folders for tests.

#include <catch2/catch.hpp>

#include <filesystem>
#include <string>
#include <system_error>
#include <unistd.h>

namespace sprig::test {

/// An empty folder `sprig-test-NAME` under the system temporary folder (removed and
/// recreated on each call); the test removes it when done.
inline std::filesystem::path scratchDir(const std::string& name) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("sprig-test-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// A new folder `sprig-NAME-XXXXXX` (a unique suffix, so parallel tests never share it)
/// under the system temporary folder; removed with its contents when the object goes.
struct TempDir {
  std::filesystem::path path;

  explicit TempDir(const std::string& name) {
    std::string p = (std::filesystem::temp_directory_path() / ("sprig-" + name + "-XXXXXX")).string();
    REQUIRE(::mkdtemp(p.data()));
    path = p;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace sprig::test
