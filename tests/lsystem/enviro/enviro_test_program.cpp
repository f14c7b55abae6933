/// A small environmental program for Sprig's tests of cpfg's `-e FILE.e` (docs/GRAMMAR.md,
/// "Environmental programs"). It speaks the same protocol as vlab's programs, over the
/// transport the environment file names (pipes, files, or shared memory with a semaphore
/// pair), so that the same object runs under cpfg and under Sprig.
///
///   sprig_enviro_test [-e FILE.e] [-k KEY] [-ext EXT] MODE [ARG]
///
/// MODE `field`: each `?E` gets, in order, x*x + y of the turtle's position, the heading's
///   y, then nothing (left unset), for as many parameters as it has.
/// MODE `occupancy CELL`: the first `?E` in a cell of size CELL (the grid rounds x, y, z
///   down) gets 1 and claims the cell for good; later ones in a claimed cell get 0.
/// Misbehaviours, for the client's error paths: `exit` (exits at the first queries),
///   `garbage` (a malformed answer), `hang` (never answers), `nostart` (never signals that
///   it runs), `wrongdist` (answers for a module it was not sent).

#include <sys/ipc.h>
#include <sys/sem.h>
#include <sys/shm.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

namespace {

enum class Transport { Pipes, Files, Memory };

struct Setup {
  Transport transport = Transport::Pipes;
  std::vector<size_t> turtleSkips;  // per turtle line sent: characters before its first '%'
  int headingLine = -1;             // which turtle line is the heading (-1: none)
  std::string ext;
  int key = 0;
  std::string mode = "field";
  double cell = 1.0;
};

void readEnvironmentFile(const std::string& path, Setup& s) {
  std::ifstream in(path);
  const char* order[] = {"turtle position", "turtle heading", "turtle left", "turtle up"};
  size_t skips[4];
  bool present[4] = {false, false, false, false};
  for (std::string line; std::getline(in, line);) {
    const size_t cut = line.find_first_of("\t:");
    if (cut == std::string::npos) continue;
    const std::string key = line.substr(0, cut), rest = line.substr(cut + 1);
    if (key == "communication type") {
      if (rest.find("files") != std::string::npos) s.transport = Transport::Files;
      if (rest.find("memory") != std::string::npos) s.transport = Transport::Memory;
    }
    for (int k = 0; k < 4; ++k)
      if (key == order[k]) present[k] = true, skips[k] = rest.find('%');
  }
  for (int k = 0; k < 4; ++k)
    if (present[k]) {
      if (k == 1) s.headingLine = static_cast<int>(s.turtleSkips.size());
      s.turtleSkips.push_back(skips[k]);
    }
}

/// The master's chunk of text and our answers, over the transport.
struct Channel {
  Setup& s;
  int semid = -1;
  char* shm = nullptr;

  explicit Channel(Setup& setup) : s(setup) {
    if (s.transport == Transport::Pipes) {
      std::fputc(1, stdout);  // "running"
      std::fflush(stdout);
      return;
    }
    semid = semget(s.key, 2, 0600);
    if (semid < 0) std::exit(3);
    if (s.transport == Transport::Memory) {
      const int shmid = shmget(s.key - 1, 60000, 0600);
      if (shmid < 0) std::exit(3);
      shm = static_cast<char*>(shmat(shmid, nullptr, 0));
    }
    semctl(semid, 1, SETVAL, 0);  // "running"
  }
  void semOp(unsigned short n, short op) {
    sembuf b{n, op, 0};
    semop(semid, &b, 1);
  }
  /// The lines of the next chunk, up to and including its Control line.
  std::vector<std::string> receive() {
    std::vector<std::string> lines;
    std::string text;
    if (s.transport == Transport::Pipes) {
      for (std::string l; std::getline(std::cin, l);) {
        lines.push_back(l);
        if (l.rfind("Control", 0) == 0) return lines;
      }
      std::exit(0);  // the master went away
    }
    semOp(0, -1);
    if (s.transport == Transport::Files) {
      std::ifstream f(".to_field" + s.ext);
      std::ostringstream ss;
      ss << f.rdbuf();
      text = ss.str();
    } else {
      text.assign(shm, strnlen(shm, 50000));
    }
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) {
      lines.push_back(l);
      if (l.rfind("Control", 0) == 0) break;
    }
    return lines;
  }
  /// Writes answers and our Control line (answers over 9000 bytes go in several chunks to
  /// shared memory, whose answer half holds 10,000).
  void send(const std::string& answers) {
    if (s.transport == Transport::Pipes) {
      std::fputs((answers + "Control: 5\n").c_str(), stdout);
      std::fflush(stdout);
      return;
    }
    std::string rest = answers;
    while (s.transport == Transport::Memory && rest.size() > 9000) {
      const size_t cut = rest.rfind('\n', 9000) + 1;
      put(rest.substr(0, cut) + "Control: 1\n");
      semOp(1, 1);
      semOp(0, -1);
      rest.erase(0, cut);
    }
    put(rest + "Control: 5\n");
    semOp(1, 1);
  }
  void put(const std::string& text) {
    if (s.transport == Transport::Files) {
      std::ofstream(".from_field" + s.ext) << text;
    } else {
      std::memcpy(shm + 50000, text.data(), text.size());
    }
  }
};

std::vector<double> numbers(const std::string& text) {
  std::vector<double> v;
  std::istringstream in(text);
  for (double x; in >> x;) v.push_back(x);
  return v;
}

/// The answer to one item (its line and its turtle lines), or "" for none.
std::string answer(const Setup& s, const std::string& item, const std::vector<std::string>& turtle,
                   std::map<std::tuple<long, long, long>, bool>& claimed) {
  const unsigned long dist = std::strtoul(item.c_str(), nullptr, 10);
  const size_t e = item.find('E');
  size_t nparams = 0;
  if (e != std::string::npos && item[e + 1] == '(') {
    const std::string body = item.substr(e + 2, item.find(')', e) - e - 2);
    nparams = 1 + static_cast<size_t>(std::count(body.begin(), body.end(), ','));
  }
  std::vector<double> pos = turtle.empty() ? std::vector<double>{} : numbers(turtle[0].substr(s.turtleSkips[0]));
  pos.resize(3, 0.0);
  std::vector<std::string> vals;
  if (s.mode == "occupancy") {
    auto k = std::make_tuple(static_cast<long>(std::floor(pos[0] / s.cell)), static_cast<long>(std::floor(pos[1] / s.cell)),
                             static_cast<long>(std::floor(pos[2] / s.cell)));
    const bool free = !claimed[k];
    claimed[k] = true;
    vals.push_back(free ? "1" : "0");
  } else {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", pos[0] * pos[0] + pos[1]);
    vals.push_back(buf);
    if (s.headingLine >= 0) {
      std::vector<double> h = numbers(turtle[static_cast<size_t>(s.headingLine)].substr(s.turtleSkips[static_cast<size_t>(s.headingLine)]));
      h.resize(3, 0.0);
      std::snprintf(buf, sizeof buf, "%g", h[1]);
      vals.push_back(buf);
    }
  }
  vals.resize(std::max<size_t>(nparams, 1));
  if (nparams == 0) return "";
  std::string out = std::to_string(s.mode == "wrongdist" ? dist + 99991 : dist) + " E(";
  for (size_t i = 0; i < nparams; ++i) out += (i ? "," : "") + vals[i];
  return out + ")\n";
}

}  // namespace

int main(int argc, char** argv) {
  Setup s;
  std::string efile;
  int i = 1;
  for (; i + 1 < argc && argv[i][0] == '-'; i += 2) {
    const std::string a = argv[i];
    if (a == "-ext") s.ext = argv[i + 1];
    else if (a == "-e") efile = argv[i + 1];
    else if (a == "-k") s.key = std::atoi(argv[i + 1]);
  }
  if (i < argc) s.mode = argv[i];
  if (i + 1 < argc) s.cell = std::atof(argv[i + 1]);
  if (!efile.empty()) readEnvironmentFile(efile, s);
  if (s.mode == "nostart") {
    for (;;) pause();
  }
  Channel ch(s);
  std::map<std::tuple<long, long, long>, bool> claimed;
  for (;;) {
    std::vector<std::string> lines = ch.receive();
    const std::string control = lines.empty() ? "" : lines.back();
    const int flag = std::atoi(control.c_str() + 8);
    if (flag & 8) {  // exit
      if (s.transport == Transport::Pipes) {
        std::fputs("Control: 5\n\x01", stdout);
        std::fflush(stdout);
      } else {
        ch.send("");
      }
      return 0;
    }
    if (s.mode == "exit") return 4;
    if (s.mode == "hang") {
      for (;;) pause();
    }
    std::string answers;
    const size_t per = 1 + s.turtleSkips.size();
    for (size_t k = 0; k + per <= lines.size() - 1; k += per) {
      std::vector<std::string> turtle(lines.begin() + static_cast<long>(k) + 1, lines.begin() + static_cast<long>(k + per));
      answers += answer(s, lines[k], turtle, claimed);
    }
    if (s.mode == "garbage") answers = "this is no answer\n";
    ch.send(answers);
  }
}
