#pragma once
/// Waiting for files to change (`sprig preview --watch`, `sprig render --watch`).
///
/// A FileWatcher holds a set of files and the content each had when it was last looked at
/// (a 64-bit FNV-1a hash of the bytes, or "missing"). waitForChange() returns once some
/// file's content differs. Editors save in many ways (write in place, write a new file and
/// rename it over the old, delete and recreate), so the watcher never follows a file's
/// inode: on Linux it asks inotify about the *folders* that hold the files and, on any event
/// there, compares contents; a touch that leaves the bytes alone is not a change. Where
/// inotify is missing or refused (other systems, some network file systems, the limit on
/// watches reached) and with `Mode::Poll`, it compares contents every poll interval instead.

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace sprig {

/// Options of a FileWatcher.
struct FileWatchOptions {
  enum class Mode { Auto, Poll };
  Mode mode = Mode::Auto;  ///< Auto: inotify where it works, else polling
  std::chrono::milliseconds pollInterval{250};  ///< polling: time between content checks
  /// After the first sign of a change, wait this long for the editor to finish writing
  /// (several writes and a rename often follow one another) before comparing.
  std::chrono::milliseconds settle{60};
};

/// Watches a set of files for changes of their content. Not thread-safe.
class FileWatcher {
 public:
  explicit FileWatcher(FileWatchOptions options = {});
  ~FileWatcher();
  FileWatcher(const FileWatcher&) = delete;
  FileWatcher& operator=(const FileWatcher&) = delete;

  /// Replaces the watched set and records each file's content now (a missing file is
  /// watched for its creation).
  void watch(const std::vector<std::filesystem::path>& files);
  /// Blocks until the content of a watched file differs from what was recorded, or until
  /// timeout (nullopt: no limit). Returns the changed files (recording their new content),
  /// or an empty list on timeout.
  std::vector<std::filesystem::path> waitForChange(std::optional<std::chrono::milliseconds> timeout = std::nullopt);
  /// True when changes are found through inotify, false when by polling.
  bool usesInotify() const { return inotifyFd_ >= 0; }

  /// 64-bit FNV-1a of the file's bytes; nullopt when it cannot be read.
  static std::optional<uint64_t> contentHash(const std::filesystem::path& file);

 private:
  struct Entry {
    std::filesystem::path path;
    std::optional<uint64_t> hash;
  };
  std::vector<std::filesystem::path> changedFiles();
  void closeWatches();

  FileWatchOptions options_;
  std::vector<Entry> files_;
  int inotifyFd_ = -1;
  std::vector<int> watches_;
};

}  // namespace sprig
