#include "core/file_watch.h"

#include <algorithm>
#include <set>
#include <thread>

#if defined(__linux__)
#include <poll.h>
#include <sys/inotify.h>
#include <unistd.h>
#endif

#include "core/atomic_file.h"

namespace sprig {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

FileWatcher::FileWatcher(FileWatchOptions options) : options_(options) {
#if defined(__linux__)
  if (options_.mode == FileWatchOptions::Mode::Auto) inotifyFd_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
#endif
}

FileWatcher::~FileWatcher() {
  closeWatches();
#if defined(__linux__)
  if (inotifyFd_ >= 0) ::close(inotifyFd_);
#endif
}

void FileWatcher::closeWatches() {
#if defined(__linux__)
  for (int w : watches_) inotify_rm_watch(inotifyFd_, w);
#endif
  watches_.clear();
}

std::optional<uint64_t> FileWatcher::contentHash(const fs::path& file) {
  std::string bytes;
  try {
    bytes = readFile(file);  // regular files only: a FIFO never blocks the watch
  } catch (const std::exception&) {
    return std::nullopt;
  }
  uint64_t h = 1469598103934665603ull;
  for (char c : bytes) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

void FileWatcher::watch(const std::vector<fs::path>& files) {
  files_.clear();
  for (const fs::path& f : files) files_.push_back(Entry{f, contentHash(f)});
#if defined(__linux__)
  if (inotifyFd_ < 0) return;
  closeWatches();
  std::set<fs::path> folders;
  for (const fs::path& f : files) {
    fs::path folder = f.parent_path();
    folders.insert(folder.empty() ? fs::path(".") : folder);
  }
  for (const fs::path& folder : folders) {
    const int w = inotify_add_watch(inotifyFd_, folder.c_str(),
                                    IN_CLOSE_WRITE | IN_MOVED_TO | IN_CREATE | IN_DELETE | IN_MODIFY | IN_ATTRIB);
    if (w < 0) {  // no such folder, no permission, limit reached: poll instead
      closeWatches();
      ::close(inotifyFd_);
      inotifyFd_ = -1;
      return;
    }
    watches_.push_back(w);
  }
#endif
}

std::vector<fs::path> FileWatcher::changedFiles() {
  std::vector<fs::path> out;
  for (Entry& e : files_) {
    std::optional<uint64_t> h = contentHash(e.path);
    if (h != e.hash) {
      e.hash = h;
      out.push_back(e.path);
    }
  }
  return out;
}

std::vector<fs::path> FileWatcher::waitForChange(std::optional<std::chrono::milliseconds> timeout) {
  const auto deadline = timeout ? Clock::now() + *timeout : Clock::time_point::max();
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return {};
#if defined(__linux__)
    if (inotifyFd_ >= 0) {
      // Sleep until something happens in a watched folder (at most a second, so a missed
      // event still gets a content check).
      pollfd p{inotifyFd_, POLLIN, 0};
      const int wait = static_cast<int>(std::min<int64_t>(left.count(), 1000));
      if (::poll(&p, 1, wait) > 0) {
        std::this_thread::sleep_for(options_.settle);
        char buffer[8192];
        while (::read(inotifyFd_, buffer, sizeof buffer) > 0) {
        }
      }
      std::vector<fs::path> changed = changedFiles();
      if (!changed.empty()) return changed;
      continue;
    }
#endif
    std::this_thread::sleep_for(std::min(left, options_.pollInterval));
    std::vector<fs::path> changed = changedFiles();
    if (!changed.empty()) {
      std::this_thread::sleep_for(options_.settle);
      changedFiles();  // the editor's last writes, recorded so they do not count twice
      return changed;
    }
  }
}

}  // namespace sprig
