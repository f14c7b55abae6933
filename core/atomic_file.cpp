#include "core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/diagnostics.h"
#include "core/progress.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

// Live temporaries, kept as fixed C strings so a signal handler can unlink them.
constexpr int kMaxLive = 256;
constexpr size_t kMaxPathLen = 4096;
char gLive[kMaxLive][kMaxPathLen];
std::atomic<bool> gUsed[kMaxLive];
std::mutex gLiveMutex;
std::atomic<uint64_t> gCounter{0};

int registerLive(const fs::path& p) {
  std::string s = p.string();
  if (s.size() >= kMaxPathLen) return -1;
  std::lock_guard<std::mutex> lock(gLiveMutex);
  for (int i = 0; i < kMaxLive; ++i) {
    if (!gUsed[i].load()) {
      std::memcpy(gLive[i], s.c_str(), s.size() + 1);
      gUsed[i].store(true);
      return i;
    }
  }
  return -1;
}

void unregisterLive(const fs::path& p) {
  std::string s = p.string();
  std::lock_guard<std::mutex> lock(gLiveMutex);
  for (int i = 0; i < kMaxLive; ++i)
    if (gUsed[i].load() && s == gLive[i]) { gUsed[i].store(false); return; }
}

extern "C" void onTerminatingSignal(int sig) {
  for (int i = 0; i < kMaxLive; ++i)
    if (gUsed[i].load()) unlink(gLive[i]);
  ProgressSettings::requestCancel();
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

TempPath::TempPath(fs::path destination) : destination_(std::move(destination)) {
  fs::path dir = destination_.parent_path();
  std::string name = ".sprig-tmp-" + std::to_string(getpid()) + "-" + std::to_string(gCounter.fetch_add(1)) + "-" +
                     destination_.filename().string();
  temp_ = dir.empty() ? fs::path(name) : dir / name;
  registerLive(temp_);
}

TempPath::~TempPath() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(temp_, ec);
  }
  unregisterLive(temp_);
}

void TempPath::commit() {
  std::error_code ec;
  fs::rename(temp_, destination_, ec);
  if (ec) throw std::runtime_error("cannot write '" + destination_.string() + "': " + ec.message());
  committed_ = true;
}

void writeFileAtomic(const fs::path& path, std::string_view bytes) {
  TempPath tmp(path);
  {
    std::ofstream out(tmp.path(), std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write '" + path.string() + "': " + std::strerror(errno));
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) throw std::runtime_error("cannot write '" + path.string() + "': write failed");
  }
  tmp.commit();
}

namespace {

/// FileReadError's message: `cannot find file 'P'`, `'P': cannot ...` or `'P' is a FIFO, ...`.
std::string fileReadMessage(const fs::path& path, const std::string& reason) {
  const std::string quoted = "'" + path.string() + "'";
  if (reason == "cannot find file") return reason + " " + quoted;
  return quoted + (reason.rfind("cannot ", 0) == 0 ? ": " : " ") + reason;
}

}  // namespace

FileReadError::FileReadError(const fs::path& path, std::string reason)
    : std::runtime_error(fileReadMessage(path, reason)), reason_(std::move(reason)) {}

namespace {

/// notRegularFileReason of a stat result.
std::string reasonOfMode(mode_t mode) {
  if (S_ISREG(mode)) return {};
  if (S_ISDIR(mode)) return "is a folder, not a regular file";
  if (S_ISFIFO(mode)) return "is a FIFO, not a regular file";
  if (S_ISSOCK(mode)) return "is a socket, not a regular file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "is a device, not a regular file";
  return "is not a regular file";
}

/// Closes a descriptor when it goes out of scope.
struct FdCloser {
  int fd;
  ~FdCloser() { ::close(fd); }
};

}  // namespace

std::string notRegularFileReason(const fs::path& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return errno == ENOENT || errno == ENOTDIR ? "cannot find file" : std::string("cannot read it: ") + std::strerror(errno);
  return reasonOfMode(st.st_mode);
}

void requireRegularFile(const fs::path& path) {
  std::string reason = notRegularFileReason(path);
  if (!reason.empty()) throw FileReadError(path, std::move(reason));
}

std::string readFile(const fs::path& path, uint64_t maxBytes) {
  requireRegularFile(path);
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw FileReadError(path, std::string("cannot read it: ") + std::strerror(errno));
  FdCloser closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw FileReadError(path, std::string("cannot read it: ") + std::strerror(errno));
  if (std::string reason = reasonOfMode(st.st_mode); !reason.empty()) throw FileReadError(path, std::move(reason));
  const uint64_t size = static_cast<uint64_t>(st.st_size);
  if (size > maxBytes)
    throw FileReadError(path, "has " + std::to_string(size) + " bytes, more than the limit of " + std::to_string(maxBytes) + " bytes");
  std::string bytes;
  bytes.reserve(size);
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw FileReadError(path, std::string("cannot read it: ") + std::strerror(errno));
    if (n == 0) break;
    if (bytes.size() + static_cast<uint64_t>(n) > maxBytes)  // the file grew while read
      throw FileReadError(path, "has more than the limit of " + std::to_string(maxBytes) + " bytes");
    bytes.append(buffer, static_cast<size_t>(n));
  }
  return bytes;
}

std::string readInputFile(const fs::path& path, const std::string& displayPath, uint64_t maxBytes,
                          const std::string& limitName) {
  try {
    return readFile(path, maxBytes);
  } catch (const FileReadError& e) {
    std::string reason = e.reason();
    if (reason.find("the limit of") != std::string::npos) reason = "the file " + reason + " (" + limitName + ")";
    throw InputError(SourceLoc{displayPath}, reason);
  }
}

int removeStaleTemporaries(const fs::path& folder) {
  int n = 0;
  std::error_code ec;
  for (auto it = fs::directory_iterator(folder, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    if (it->path().filename().string().rfind(".sprig-tmp-", 0) == 0) {
      std::error_code rec;
      if (fs::remove(it->path(), rec)) ++n;
    }
  }
  return n;
}

void installSignalCleanup() {
  std::signal(SIGINT, onTerminatingSignal);
  std::signal(SIGTERM, onTerminatingSignal);
}

}  // namespace sprig
