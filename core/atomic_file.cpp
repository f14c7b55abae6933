#include "core/atomic_file.h"

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

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read '" + path.string() + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string readInputFile(const fs::path& path, const std::string& displayPath, uint64_t maxBytes,
                          const std::string& what, const std::string& limitName) {
  std::error_code ec;
  const uint64_t size = fs::file_size(path, ec);
  if (ec) throw InputError(SourceLoc{displayPath}, "cannot read this " + what + " file: " + ec.message());
  if (size > maxBytes)
    throw InputError(SourceLoc{displayPath}, "the file has " + std::to_string(size) + " bytes, more than the limit of " +
                                                 std::to_string(maxBytes) + " bytes (" + limitName + ")");
  std::string bytes(size, '\0');
  std::ifstream f(path, std::ios::binary);
  if (!f || !f.read(bytes.data(), std::streamsize(size)))
    throw InputError(SourceLoc{displayPath}, "cannot read this " + what + " file");
  return bytes;
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
