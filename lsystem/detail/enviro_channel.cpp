#include "lsystem/detail/enviro_channel.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/ipc.h>
#include <sys/sem.h>
#include <sys/shm.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "core/diagnostics.h"

extern char** environ;

namespace sprig::lsystem::detail {

namespace {

using Clock = std::chrono::steady_clock;
using Transport = EnvironmentSpec::Transport;

/// vlab's shared memory block (communication.h): the queries, then the answers.
constexpr size_t kToFieldBytes = 50000;
constexpr size_t kFromFieldBytes = 10000;
/// How long the program may take to leave after cpfg's exit message before SIGKILL.
constexpr double kExitGraceSeconds = 2.0;

bool startsWith(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }

/// The program's path: a name with '/' relative to workDir, else looked up on PATH (as
/// cpfg's `which`); empty when not found or not executable.
std::string resolveProgram(const std::string& name, const std::string& workDir) {
  auto executable = [](const std::string& p) {
    struct stat st {};
    return ::stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(p.c_str(), X_OK) == 0;
  };
  if (name.find('/') != std::string::npos) {
    std::string p = name[0] == '/' ? name : workDir + "/" + name;
    return executable(p) ? p : std::string();
  }
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    std::string p = (d.empty() ? "." : d) + "/" + name;
    if (executable(p)) return p;
  }
  return {};
}

void sem(int semid, unsigned short num, short op) {
  sembuf b{num, op, 0};
  while (::semop(semid, &b, 1) != 0 && errno == EINTR) {
  }
}

}  // namespace

struct EnviroChannel::State {
  EnvironmentSpec spec;
  std::string workDir;
  double timeout = 60;
  pid_t pid = -1;
  bool exited = false;   ///< reaped
  bool broken = false;   ///< a failure: kill without the exit message
  // pipes
  int toFd = -1, fromFd = -1;
  // files and memory
  int semid = -1, shmid = -1;
  char* shm = nullptr;
  std::string ext, toPath, fromPath;
  // the chunk being written, the answers being read
  std::string out;
  int items = 0;
  std::string in;
  size_t inPos = 0;
  bool inLoaded = false;

  std::string who() const {
    return "environmental program '" + spec.command.front() + "' (" + spec.file + ")";
  }
  [[noreturn]] void fail(const std::string& what) {
    broken = true;
    throw InputError(SourceLoc{"sprig", 0, 0}, who() + " " + what);
  }

  /// Fails when the program has exited (reaping it).
  void checkAlive() {
    if (exited || pid < 0) fail("is not running");
    int st = 0;
    if (::waitpid(pid, &st, WNOHANG) == pid) {
      exited = true;
      if (WIFSIGNALED(st)) fail("was killed by signal " + std::to_string(WTERMSIG(st)) + " before it answered");
      fail("exited (status " + std::to_string(WEXITSTATUS(st)) + ") before it answered");
    }
  }
  double secondsSince(Clock::time_point t0) const {
    return std::chrono::duration<double>(Clock::now() - t0).count();
  }
  void checkTime(Clock::time_point t0, const char* what) {
    if (secondsSince(t0) > timeout) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%g", timeout);
      fail(std::string("did not ") + what + " within " + buf + " s (--enviro-timeout)");
    }
  }
  /// The program closed its side of a pipe: it is exiting, so give it a second to be
  /// reaped (its status is the better message), else report the closed pipe.
  [[noreturn]] void closed(const char* what) {
    const auto t0 = Clock::now();
    while (secondsSince(t0) < 1.0) {
      checkAlive();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    fail(what);
  }

  // -------------------------------------------------------------- start
  std::vector<std::string> arguments(const std::string& program, int key) const {
    const std::vector<std::string>& c = spec.command;
    std::vector<std::string> a{program};
    const bool pipes = spec.transport == Transport::Pipes;
    // cpfg adds `-e FILE.e` when the command's second word is not -e (pipes: only when it
    // has one), then, for files and memory, the semaphore key and the files' suffix.
    const bool addE = pipes ? c.size() > 1 && !startsWith(c[1], "-e") : c.size() < 2 || !startsWith(c[1], "-e");
    if (addE) a.insert(a.end(), {"-e", std::filesystem::absolute(spec.file).string()});  // it runs in workDir
    if (!pipes) a.insert(a.end(), {"-k", std::to_string(key)});
    if (spec.transport == Transport::Files) a.insert(a.end(), {"-ext", ext});
    a.insert(a.end(), c.begin() + 1, c.end());
    return a;
  }

  void spawn(const std::string& program, const std::vector<std::string>& args, int childIn, int childOut) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addchdir_np(&fa, workDir.c_str());
    if (childIn >= 0) {
      posix_spawn_file_actions_adddup2(&fa, childIn, 0);
      posix_spawn_file_actions_adddup2(&fa, childOut, 1);
    } else {
      posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
      posix_spawn_file_actions_adddup2(&fa, 2, 1);  // its messages must not mix with Sprig's output
    }
    std::vector<char*> argv;
    for (const std::string& s : args) argv.push_back(const_cast<char*>(s.c_str()));
    argv.push_back(nullptr);
    const int rc = posix_spawn(&pid, program.c_str(), &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (rc != 0) {
      pid = -1;
      fail(std::string("cannot be started: ") + std::strerror(rc));
    }
  }

  void startPipes(const std::string& program) {
    int to[2], from[2];
    if (::pipe2(to, O_CLOEXEC) != 0) fail("cannot be started: no pipe");
    if (::pipe2(from, O_CLOEXEC) != 0) {
      ::close(to[0]);
      ::close(to[1]);
      fail("cannot be started: no pipe");
    }
    toFd = to[1];
    fromFd = from[0];
    spawn(program, arguments(program, 0), to[0], from[1]);
    ::close(to[0]);
    ::close(from[1]);
    // vlab's programs write a byte 1 as soon as they run (comm_slave.c, CSInitialize).
    char c = 0;
    readSome(&c, 1, "start");
    if (c != 1) fail("did not send the start byte (is it an environmental program?)");
  }

  /// A semaphore pair (and for memory the shared block) under a key no one else uses.
  int makeIpc() {
    const int base = static_cast<int>((static_cast<unsigned>(::getpid()) << 2) & 0xffffu);
    for (int t = 0; t < 16384; ++t) {
      const int key = (base + 4 * t) & 0xffff;
      if (key < 2) continue;
      semid = ::semget(key, 2, IPC_CREAT | IPC_EXCL | 0600);
      if (semid < 0) continue;
      if (spec.transport == Transport::Memory) {
        shmid = ::shmget(key - 1, kToFieldBytes + kFromFieldBytes, IPC_CREAT | IPC_EXCL | 0600);
        if (shmid < 0) {
          ::semctl(semid, 0, IPC_RMID);
          semid = -1;
          continue;
        }
        void* p = ::shmat(shmid, nullptr, 0);
        if (p == reinterpret_cast<void*>(-1)) fail("cannot be started: no shared memory");
        shm = static_cast<char*>(p);
      }
      ::semctl(semid, 0, SETVAL, 0);
      ::semctl(semid, 1, SETVAL, 1);
      return key;
    }
    fail("cannot be started: no free semaphore key");
  }

  void startSemaphores(const std::string& program) {
    const int key = makeIpc();
    ext = std::to_string(::getpid()) + "." + std::to_string(key);
    toPath = workDir + "/.to_field" + ext;
    fromPath = workDir + "/.from_field" + ext;
    spawn(program, arguments(program, key), -1, -1);
    // The program clears semaphore 1 as soon as it runs (comm_slave.c, InitializeSemaphores).
    const auto t0 = Clock::now();
    while (::semctl(semid, 1, GETVAL) != 0) {
      checkAlive();
      checkTime(t0, "start");
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }

  // -------------------------------------------------------------- pipes
  /// Reads exactly n bytes from the program's output.
  void readSome(char* buf, size_t n, const char* what) {
    const auto t0 = Clock::now();
    size_t got = 0;
    while (got < n) {
      pollfd p{fromFd, POLLIN, 0};
      const int r = ::poll(&p, 1, 100);
      if (r > 0) {
        const ssize_t k = ::read(fromFd, buf + got, n - got);
        if (k == 0) closed("closed its output before it started");
        if (k > 0) got += static_cast<size_t>(k);
        continue;
      }
      checkAlive();
      checkTime(t0, what);
    }
  }

  /// Writes s to the program's input, reading its output meanwhile (it may answer while
  /// it reads), so neither side blocks on a full pipe.
  void writePipe(const std::string& s) {
    const auto t0 = Clock::now();
    size_t done = 0;
    while (done < s.size()) {
      pollfd p[2] = {{toFd, POLLOUT, 0}, {fromFd, POLLIN, 0}};
      const int r = ::poll(p, 2, 100);
      if (r <= 0) {
        checkAlive();
        checkTime(t0, "read its input");
        continue;
      }
      if (p[1].revents & POLLIN) {
        char buf[4096];
        const ssize_t k = ::read(fromFd, buf, sizeof buf);
        if (k > 0) in.append(buf, static_cast<size_t>(k));
      }
      if (p[0].revents & (POLLERR | POLLHUP)) closed("closed its input");
      if (p[0].revents & POLLOUT) {
        const ssize_t k = ::write(toFd, s.data() + done, s.size() - done);
        if (k > 0) done += static_cast<size_t>(k);
        else if (k < 0 && errno != EAGAIN && errno != EINTR) closed("closed its input");
      }
    }
  }

  // -------------------------------------------------------------- files and memory
  /// cpfg's LetSlaveRunAndWait: raise semaphore 0, wait for semaphore 1.
  void letRun() {
    sem(semid, 0, 1);
    const auto t0 = Clock::now();
    for (;;) {
      sembuf b{1, -1, 0};
      timespec ts{0, 100'000'000};
      if (::semtimedop(semid, &b, 1, &ts) == 0) break;
      if (errno != EAGAIN && errno != EINTR) fail("cannot be waited for: semaphore lost");
      checkAlive();
      checkTime(t0, "answer");
    }
    inLoaded = false;
  }

  /// The answers the program wrote (its file, or its half of the shared block).
  void loadAnswers() {
    in.clear();
    inPos = 0;
    if (spec.transport == Transport::Files) {
      std::ifstream f(fromPath, std::ios::binary);
      if (!f) fail("wrote no answer file");
      std::ostringstream ss;
      ss << f.rdbuf();
      in = ss.str();
    } else {
      const char* p = shm + kToFieldBytes;
      in.assign(p, ::strnlen(p, kFromFieldBytes));
    }
    inLoaded = true;
  }

  // -------------------------------------------------------------- answers
  /// The next line of the program's answers (without '\n').
  std::string nextLine() {
    if (spec.transport != Transport::Pipes && !inLoaded) loadAnswers();
    for (;;) {
      const size_t nl = in.find('\n', inPos);
      if (nl != std::string::npos) {
        std::string line = in.substr(inPos, nl - inPos);
        inPos = nl + 1;
        return line;
      }
      if (spec.transport != Transport::Pipes) {
        // shared memory holds no end: the Control line ends the answers
        if (spec.transport == Transport::Memory && startsWith(in.substr(inPos), "Control")) {
          std::string line = in.substr(inPos);
          inPos = in.size();
          return line;
        }
        fail("ended its answers without a 'Control:' line");
      }
      in.erase(0, inPos);
      inPos = 0;
      char buf[4096];
      pollfd p{fromFd, POLLIN, 0};
      const auto t0 = Clock::now();
      while (::poll(&p, 1, 100) <= 0) {
        checkAlive();
        checkTime(t0, "answer");
      }
      const ssize_t k = ::read(fromFd, buf, sizeof buf);
      if (k <= 0) closed("closed its output before it answered");
      in.append(buf, static_cast<size_t>(k));
    }
  }

  // -------------------------------------------------------------- end
  /// cpfg's exit message, then up to kExitGraceSeconds for the program to leave; SIGKILL
  /// after that (or at once after a failure); always reaped; IPC objects and files removed.
  void shutdown() noexcept {
    if (pid > 0 && !exited) {
      if (!broken) {
        try {
          const std::string bye = "Control: " + std::to_string(kProcessExit) + " 0\n";
          if (spec.transport == Transport::Pipes) {
            const ssize_t k = ::write(toFd, bye.data(), bye.size());
            (void)k;
          } else {
            out = bye;
            flushChunk();
            sem(semid, 0, 1);
          }
        } catch (...) {
        }
      }
      if (toFd >= 0) ::close(toFd), toFd = -1;
      const auto t0 = Clock::now();
      int st = 0;
      while (!broken && secondsSince(t0) < kExitGraceSeconds && ::waitpid(pid, &st, WNOHANG) == 0)
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      if (::waitpid(pid, &st, WNOHANG) == 0) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &st, 0);
      }
      exited = true;
    }
    if (toFd >= 0) ::close(toFd);
    if (fromFd >= 0) ::close(fromFd);
    toFd = fromFd = -1;
    if (shm) ::shmdt(shm), shm = nullptr;
    if (shmid >= 0) ::shmctl(shmid, IPC_RMID, nullptr), shmid = -1;
    if (semid >= 0) ::semctl(semid, 0, IPC_RMID), semid = -1;
    if (!toPath.empty()) ::unlink(toPath.c_str());
    if (!fromPath.empty()) ::unlink(fromPath.c_str());
  }

  /// Hands the chunk in `out` over: the query file, or the shared block.
  void flushChunk() {
    if (spec.transport == Transport::Pipes) {
      writePipe(out);
    } else if (spec.transport == Transport::Files) {
      std::ofstream f(toPath, std::ios::binary | std::ios::trunc);
      f << out;
      if (!f.flush()) fail("cannot be given its queries: cannot write " + toPath);
    } else {
      std::memcpy(shm, out.data(), std::min(out.size(), kToFieldBytes));
    }
    out.clear();
  }
};

std::unique_ptr<EnviroChannel> EnviroChannel::start(const EnvironmentSpec& spec, const std::string& workDir,
                                                    double timeoutSeconds) {
  std::unique_ptr<EnviroChannel> ch(new EnviroChannel());
  ch->s_ = std::make_unique<State>();
  State& s = *ch->s_;
  s.spec = spec;
  s.workDir = workDir;
  s.timeout = timeoutSeconds;
  struct sigaction ign {};
  ign.sa_handler = SIG_IGN;
  ::sigaction(SIGPIPE, &ign, nullptr);  // a program that dies mid-write is an error, not a signal
  const std::string program = resolveProgram(spec.command.front(), workDir);
  if (program.empty())
    s.fail(spec.command.front().find('/') != std::string::npos ? "is not an executable file in " + workDir
                                                                 : "was not found on PATH");
  if (spec.transport == Transport::Pipes) s.startPipes(program);
  else s.startSemaphores(program);
  return ch;
}

EnviroChannel::~EnviroChannel() {
  if (s_) s_->shutdown();
}

void EnviroChannel::beginChunk() {
  s_->out.clear();
  s_->items = 0;
}

bool EnviroChannel::fits(const std::string& item) const {
  // cpfg (communication.c, SaveOneDataItem): pipes and files count items, shared memory
  // counts bytes with 25 to spare for the Control line.
  if (s_->spec.transport == Transport::Memory) return s_->out.size() + item.size() + 25 < kToFieldBytes - 1;
  return s_->items < s_->spec.maxQueries;
}

void EnviroChannel::append(const std::string& item) {
  s_->out += item;
  ++s_->items;
}

void EnviroChannel::endChunk(int flag, int step) {
  State& s = *s_;
  s.out += "Control: " + std::to_string(flag) + " " + std::to_string(step) + "\n";
  s.flushChunk();
  if (s.spec.transport != Transport::Pipes) s.letRun();
}

bool EnviroChannel::readAnswer(std::string& line) {
  State& s = *s_;
  for (;;) {
    line = s.nextLine();
    if (!startsWith(line, "Control")) return true;
    int flag = 0;
    if (std::sscanf(line.c_str() + 7, ":%d", &flag) != 1 && std::sscanf(line.c_str() + 7, "%d", &flag) != 1)
      s.fail("sent a malformed line '" + line.substr(0, 80) + "'");
    if (flag & kLastChunk) return false;
    // more answers follow: let the program write its next chunk (files and memory)
    if (s.spec.transport != Transport::Pipes) s.letRun();
  }
}

void EnviroChannel::fail(const std::string& what) { s_->fail(what); }

}  // namespace sprig::lsystem::detail
