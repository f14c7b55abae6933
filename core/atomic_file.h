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
#include <stdexcept>
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

/// Why a file cannot be read, as readFile and requireRegularFile report it.
class FileReadError : public std::runtime_error {
 public:
  /// what() is "cannot find file 'P'", "'P' is a FIFO, not a regular file", ...;
  /// reason() is the same without the path ("cannot find file", "is a FIFO, not a regular file").
  FileReadError(const std::filesystem::path& path, std::string reason);
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

/// The reason a user-named path is not a readable regular file, from stat (symbolic links
/// followed), without opening it: "" for a regular file, else "cannot find file" (only
/// when nothing is there), "is a folder, not a regular file", "is a FIFO, not a regular
/// file", "is a socket, not a regular file", "is a device, not a regular file" or
/// "cannot read it: <system reason>".
std::string notRegularFileReason(const std::filesystem::path& path);

/// Throws FileReadError unless path is a regular file (for paths handed to a library that
/// opens them itself, such as image readers).
void requireRegularFile(const std::filesystem::path& path);

/// Reads a whole file: the one way Sprig opens a file a user named. Only a regular file
/// is read: the type is checked with stat before opening, the file is opened with
/// O_NONBLOCK (a FIFO swapped in after the check never blocks) and checked again with
/// fstat. Throws FileReadError (notRegularFileReason's reasons, or the size against
/// maxBytes) before allocating.
std::string readFile(const std::filesystem::path& path, uint64_t maxBytes = UINT64_MAX);

/// readFile for parsers: an error is an InputError at displayPath (the reason; a size
/// over maxBytes names the limit limitName).
std::string readInputFile(const std::filesystem::path& path, const std::string& displayPath, uint64_t maxBytes,
                          const std::string& limitName);

/// Removes SIGINT/SIGTERM-interrupted temporaries (`.sprig-tmp-*`) in folder (not recursive).
/// Returns how many were removed.
int removeStaleTemporaries(const std::filesystem::path& folder);

/// Installs SIGINT/SIGTERM handlers that delete live temporaries, request cancellation,
/// and re-raise the signal. Safe to call more than once.
void installSignalCleanup();

}  // namespace sprig
