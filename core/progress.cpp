#include "core/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace sprig {

namespace {
std::atomic<bool> gQuiet{false};
std::atomic<bool> gCancel{false};
std::atomic<ProgressObserver*> gObserver{nullptr};

std::string formatSeconds(double s) {
  if (!std::isfinite(s) || s < 0) return "--:--";
  long t = static_cast<long>(s + 0.5);
  char buf[32];
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", t / 60, t % 60);
  return buf;
}
}  // namespace

void ProgressSettings::setQuiet(bool quiet) { gQuiet = quiet; }
bool ProgressSettings::quiet() { return gQuiet; }
void ProgressSettings::requestCancel() { gCancel = true; }
bool ProgressSettings::cancelRequested() { return gCancel.load(std::memory_order_relaxed); }
void ProgressSettings::clearCancel() { gCancel = false; }
void ProgressSettings::setObserver(ProgressObserver* observer) { gObserver = observer; }

Progress::Progress(std::string label, uint64_t total)
    : label_(std::move(label)), total_(total), start_(std::chrono::steady_clock::now()),
      enabled_(!gQuiet && isatty(STDERR_FILENO)), observer_(gObserver.load()) {}

Progress::~Progress() {
  if (enabled_ && !finished_) {
    std::lock_guard<std::mutex> lock(drawMutex_);
    std::fputs("\n", stderr);
  }
}

double Progress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void Progress::advance(uint64_t n) {
  done_.fetch_add(n, std::memory_order_relaxed);
  if (gCancel.load(std::memory_order_relaxed)) throw Cancelled();
  if (!enabled_ && !observer_) return;
  int64_t now = std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_).count();
  int64_t due = nextDrawNs_.load(std::memory_order_relaxed);
  if (now < due) return;
  if (!nextDrawNs_.compare_exchange_strong(due, now + 100'000'000)) return;
  if (observer_) observer_->update(label_, done_.load(std::memory_order_relaxed), total_);
  if (!enabled_) return;
  std::unique_lock<std::mutex> lock(drawMutex_, std::try_to_lock);
  if (lock.owns_lock()) draw(false);
}

void Progress::finish() {
  if (finished_) return;
  if (observer_) observer_->update(label_, done_.load(std::memory_order_relaxed), total_);
  if (enabled_) {
    std::lock_guard<std::mutex> lock(drawMutex_);
    draw(true);
    std::fputs("\n", stderr);
  }
  finished_ = true;
}

void Progress::draw(bool final) {
  uint64_t done = done_.load(std::memory_order_relaxed);
  double t = elapsed();
  char line[256];
  if (total_ > 0) {
    double frac = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_));
    constexpr int kWidth = 30;
    int filled = static_cast<int>(frac * kWidth);
    char bar[kWidth + 1];
    for (int i = 0; i < kWidth; ++i) bar[i] = i < filled ? '#' : '.';
    bar[kWidth] = 0;
    double eta = frac > 0 ? t * (1.0 - frac) / frac : NAN;
    std::snprintf(line, sizeof line, "\r%s [%s] %5.1f%%  %s elapsed  ETA %s ", label_.c_str(), bar, 100.0 * frac,
                  formatSeconds(t).c_str(), final ? "00:00" : formatSeconds(eta).c_str());
  } else {
    std::snprintf(line, sizeof line, "\r%s %llu  %s elapsed ", label_.c_str(), static_cast<unsigned long long>(done),
                  formatSeconds(t).c_str());
  }
  std::fputs(line, stderr);
  std::fflush(stderr);
}

}  // namespace sprig
