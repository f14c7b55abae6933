#include "core/phases.h"

#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

namespace sprig {

namespace {

using Clock = std::chrono::steady_clock;

struct State {
  std::thread::id owner;
  bool started = false;
  Clock::time_point begin;     ///< PhaseClock::start()
  Clock::time_point last;      ///< last time charged
  double startup = 0;          ///< process start to begin
  std::vector<std::string> names;  ///< index 0 is "other"
  std::vector<double> seconds;
  std::vector<size_t> open;    ///< stack of open phases (indices into names)
};

State& state() {
  static State s;
  return s;
}

bool onClockThread(const State& s) { return s.started && std::this_thread::get_id() == s.owner; }

/// Charges the time since the last charge to the innermost open phase (or "other").
void charge(State& s, Clock::time_point now) {
  s.seconds[s.open.empty() ? 0 : s.open.back()] += std::chrono::duration<double>(now - s.last).count();
  s.last = now;
}

/// Seconds from the process's start (field 22 of /proc/self/stat, clock ticks since boot) to
/// now (CLOCK_BOOTTIME, the same origin); 0 when either is unavailable.
double secondsSinceProcessStart() {
  std::ifstream in("/proc/self/stat");
  std::string line;
  if (!std::getline(in, line)) return 0;
  const size_t paren = line.rfind(')');
  if (paren == std::string::npos) return 0;
  std::istringstream fields(line.substr(paren + 2));
  std::string field;
  unsigned long long startTicks = 0;
  // Fields after the command name start at field 3; the start time is field 22.
  for (int i = 3; i <= 22 && fields >> field; ++i)
    if (i == 22) startTicks = std::strtoull(field.c_str(), nullptr, 10);
  const long hz = sysconf(_SC_CLK_TCK);
  timespec now{};
  if (startTicks == 0 || hz <= 0 || clock_gettime(CLOCK_BOOTTIME, &now) != 0) return 0;
  const double elapsed = double(now.tv_sec) + 1e-9 * double(now.tv_nsec) - double(startTicks) / double(hz);
  return elapsed > 0 ? elapsed : 0;
}

/// The index of phase name, added when new ("other" is index 0 and never matched).
size_t phaseIndex(State& s, const char* name) {
  size_t index = 1;
  while (index < s.names.size() && s.names[index] != name) ++index;
  if (index == s.names.size()) {
    s.names.emplace_back(name);
    s.seconds.push_back(0.0);
  }
  return index;
}

}  // namespace

void PhaseClock::declare(std::initializer_list<const char*> names) {
  State& s = state();
  if (!onClockThread(s)) return;
  for (const char* name : names) phaseIndex(s, name);
}

void PhaseClock::start() {
  State& s = state();
  s = State{};
  s.owner = std::this_thread::get_id();
  s.started = true;
  s.startup = secondsSinceProcessStart();
  s.begin = s.last = Clock::now();
  s.names = {"other"};
  s.seconds = {0.0};
}

std::vector<std::pair<std::string, double>> PhaseClock::phases() {
  State& s = state();
  if (!s.started) return {};
  if (onClockThread(s)) charge(s, Clock::now());
  std::vector<std::pair<std::string, double>> out{{"start-up", s.startup}};
  for (size_t i = 1; i < s.names.size(); ++i) out.emplace_back(s.names[i], s.seconds[i]);
  out.emplace_back("other", s.seconds[0]);
  return out;
}

double PhaseClock::total() {
  double sum = 0;
  for (const auto& [name, seconds] : phases()) sum += seconds;
  return sum;
}

namespace {

/// The phases, each printed with format (its name, then its seconds) and joined by separator;
/// sum receives their total.
std::string joinPhases(const char* format, const char* separator, double& sum) {
  std::string out;
  sum = 0;
  char buf[96];
  for (const auto& [name, seconds] : PhaseClock::phases()) {
    std::snprintf(buf, sizeof buf, format, name.c_str(), seconds);
    out += (out.empty() ? "" : separator) + std::string(buf);
    sum += seconds;
  }
  return out;
}

}  // namespace

std::string PhaseClock::summary() {
  double sum = 0;
  const std::string list = joinPhases("%s %.2f s", ", ", sum);
  char buf[48];
  std::snprintf(buf, sizeof buf, "; %.2f s wall", sum);
  return list + buf;
}

std::string PhaseClock::json(const std::string& command) {
  double sum = 0;
  const std::string body = joinPhases("\"%s\":%.6f", ",", sum);
  char buf[64];
  std::snprintf(buf, sizeof buf, "\",\"total\":%.6f,\"phases\":{", sum);
  return "{\"command\":\"" + command + buf + body + "}}";
}

Phase::Phase(const char* name) {
  State& s = state();
  if (!onClockThread(s)) return;
  active_ = true;
  charge(s, Clock::now());
  s.open.push_back(phaseIndex(s, name));
}

Phase::~Phase() {
  if (!active_) return;
  State& s = state();
  charge(s, Clock::now());
  s.open.pop_back();
}

}  // namespace sprig
