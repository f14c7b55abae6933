#pragma once
/// Atomic file output: write to a temporary file in the destination's folder, then rename.
///
/// A reader never sees a half-written file, and a failed or interrupted write leaves
/// the destination as it was. Temporary names keep the destination's extension (image
/// and mesh libraries choose the format from it) and start with `.sprig-tmp-`, so a
/// later run can recognise and remove leftovers of a killed process
/// (removeStaleTemporaries). SIGINT and SIGTERM remove the live temporaries before
/// the process ends (installSignalCleanup).

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace sprig {

/// A temporary path for `destination`; commit() renames it into place, destruction
/// without commit() deletes it.
class TempPath {
 public:
  /// Chooses a fresh `.sprig-tmp-PID-N` name beside destination (nothing is created yet).
  explicit TempPath(std::filesystem::path destination);
  ~TempPath();
  TempPath(const TempPath&) = delete;
  TempPath& operator=(const TempPath&) = delete;

  /// Where to write.
  const std::filesystem::path& path() const { return temp_; }
  /// Where commit() puts the file.
  const std::filesystem::path& destination() const { return destination_; }
  /// Renames the temporary onto the destination. Throws std::runtime_error on failure.
  void commit();

 private:
  std::filesystem::path destination_;
  std::filesystem::path temp_;
  bool committed_ = false;
};

/// Writes bytes to path atomically. Throws std::runtime_error when the folder cannot be written.
void writeFileAtomic(const std::filesystem::path& path, std::string_view bytes);

/// Reads a whole file. Throws std::runtime_error when it cannot be read.
std::string readFile(const std::filesystem::path& path);

/// Reads a whole input file of at most maxBytes bytes. Throws InputError at displayPath
/// ("cannot read this <what> file: ...", or the size against the limit named by limitName)
/// before allocating.
std::string readInputFile(const std::filesystem::path& path, const std::string& displayPath, uint64_t maxBytes,
                          const std::string& what, const std::string& limitName);

/// Removes SIGINT/SIGTERM-interrupted temporaries (`.sprig-tmp-*`) in folder (not recursive).
/// Returns how many were removed.
int removeStaleTemporaries(const std::filesystem::path& folder);

/// Installs SIGINT/SIGTERM handlers that delete live temporaries, request cancellation,
/// and re-raise the signal. Safe to call more than once.
void installSignalCleanup();

}  // namespace sprig
