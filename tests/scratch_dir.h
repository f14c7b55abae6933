#pragma once
/// A fresh scratch folder for a test.

#include <filesystem>
#include <string>

namespace sprig::test {

/// An empty folder `sprig-test-NAME` under the system temporary folder (removed and
/// recreated on each call); the test removes it when done.
inline std::filesystem::path scratchDir(const std::string& name) {
  std::filesystem::path dir = std::filesystem::temp_directory_path() / ("sprig-test-" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

}  // namespace sprig::test
