#include "lsystem/cpfg_environment.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "core/diagnostics.h"
#include "lsystem/detail/enviro_channel.h"

namespace sprig::lsystem {

namespace {

/// cpfg's directives (communication.c, ReadInEnvironmentalFile) and why Sprig refuses some.
struct Directive {
  const char* name;
  const char* unsupported;  ///< nullptr: supported
};

constexpr Directive kDirectives[] = {
    {"communication type", nullptr},
    {"executable", nullptr},
    {"turtle position", nullptr},
    {"turtle heading", nullptr},
    {"turtle left", nullptr},
    {"turtle up", nullptr},
    {"turtle line width", "the turtle's line width sent to the program"},
    {"turtle scale factor", "the turtle's scale factor sent to the program"},
    {"when interpret", "the turtle's geometry of the module after ?E sent to the program"},
    {"verbose", nullptr},
    {"remote host", "a program on another machine"},
    {"strings only", "strings instead of ?E modules"},
    {"binary data", "binary data instead of ?E modules"},
    {"interpreted modules", "the turtle's geometry of the module after ?E sent to the program"},
    {"following module", nullptr},
};

/// Number of floating conversions of a printf format, or -1 when it holds any other
/// conversion (only `%[flags][width][.precision](f|F|e|E|g|G|a|A)` and `%%` are allowed)
/// or a NUL byte (printf would stop there, maybe inside a conversion: found by fuzzing).
int floatConversions(const std::string& f) {
  if (f.find('\0') != std::string::npos) return -1;
  int n = 0;
  for (size_t i = 0; i < f.size(); ++i) {
    if (f[i] != '%') continue;
    if (++i < f.size() && f[i] == '%') continue;
    while (i < f.size() && std::strchr("-+ #0", f[i])) ++i;
    while (i < f.size() && f[i] >= '0' && f[i] <= '9') ++i;
    if (i < f.size() && f[i] == '.') {
      ++i;
      while (i < f.size() && f[i] >= '0' && f[i] <= '9') ++i;
    }
    if (i < f.size() && f[i] == 'l') ++i;
    if (i >= f.size() || !std::strchr("fFeEgGaA", f[i])) return -1;
    ++n;
  }
  return n;
}

std::vector<std::string> splitBlanks(const std::string& s) {
  std::vector<std::string> out;
  size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    size_t b = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t' && s[i] != '\r') ++i;
    if (i > b) out.push_back(s.substr(b, i - b));
  }
  return out;
}

/// One line of an environment file: its directive read into spec (errors into diags).
void readDirective(EnvironmentSpec& spec, const std::string& line, int lineNo, DiagnosticList& diags) {
  const size_t cut = line.find_first_of("\t:");
  const std::string key = line.substr(0, cut);
  const std::string rest = cut == std::string::npos ? std::string() : line.substr(cut + 1);
  const SourceLoc at{spec.file, lineNo, 1};
  const Directive* d = nullptr;
  for (const Directive& k : kDirectives)
    if (key == k.name) d = &k;
  if (!d) {
    diags.error(at, "unknown directive '" + key + "' in an environment file", line);
    return;
  }
  if (d->unsupported) {
    diags.error(at, "cpfg's environment directive '" + key + "' (" + d->unsupported + ") is not supported", line);
    return;
  }
  const std::string k = d->name;
  const std::vector<std::string> words = splitBlanks(rest);
  if (k == "communication type") {
    const std::string t = words.empty() ? "" : words[0];
    const int n = words.size() > 1 ? std::atoi(words[1].c_str()) : 0;
    if (t == "pipes") {
      spec.transport = EnvironmentSpec::Transport::Pipes;
      spec.maxQueries = n > 0 ? n : 100;
    } else if (t == "files") {
      spec.transport = EnvironmentSpec::Transport::Files;
      spec.maxQueries = n > 0 ? n : 1000;
    } else if (t == "memory") {
      spec.transport = EnvironmentSpec::Transport::Memory;
    } else if (t == "sockets") {
      diags.error(at, "cpfg's communication type 'sockets' is not supported (use pipes, files or memory)", line);
    } else {
      diags.error(at, "unknown communication type '" + t + "' (expected pipes, files or memory)", line);
    }
  } else if (k == "executable") {
    spec.command = splitBlanks(rest);
    if (!spec.command.empty() && spec.command.back() == "&") spec.command.pop_back();
    if (spec.command.empty()) diags.error(at, "'executable:' names no program", line);
  } else if (k == "following module") {
    if (!words.empty() && words[0] == "no") spec.followingModule = false;
    if (!words.empty() && words[0] == "yes") spec.followingModule = true;
  } else if (k != "verbose") {
    const int n = floatConversions(rest);
    if (n < 1 || n > 3) {
      diags.error(at, "'" + k + ":' must be a printf format with 1 to 3 floating conversions (%f, %g, %e), got '" + rest + "'", line);
      return;
    }
    std::optional<std::string>& f = k == "turtle position" ? spec.position : k == "turtle heading" ? spec.heading
                                    : k == "turtle left"   ? spec.left : spec.up;
    f = rest;
  }
}

void appendFloat(std::string& out, float v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%g", static_cast<double>(v));
  out += buf;
}

void appendModule(std::string& out, const std::string& symbol, const std::vector<float>& params) {
  out += symbol;
  if (params.empty()) return;
  out += '(';
  for (size_t i = 0; i < params.size(); ++i) {
    if (i) out += ',';
    appendFloat(out, params[i]);
  }
  out += ')';
}

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
/// One turtle vector in its validated format (floatConversions: 1 to 3 floating conversions).
void appendVector(std::string& out, const std::optional<std::string>& format, const std::array<float, 3>& v) {
  if (!format) return;
  char buf[1024];
  std::snprintf(buf, sizeof buf, format->c_str(), static_cast<double>(v[0]), static_cast<double>(v[1]),
                static_cast<double>(v[2]));
  out += buf;
  out += '\n';
}
#pragma GCC diagnostic pop

}  // namespace

EnvironmentSpec readEnvironmentFile(const std::string& path) {
  EnvironmentSpec spec;
  spec.file = path;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(SourceLoc{path, 0, 0}, "cannot read the environment file");
  DiagnosticList diags;
  std::string line;
  int lineNo = 0;
  while (std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    readDirective(spec, line, lineNo, diags);
  }
  if (spec.command.empty() && !diags.hasErrors())
    diags.error(SourceLoc{path, 0, 0}, "the environment file names no program ('executable:')");
  diags.throwIfErrors();
  return spec;
}

std::string formatEnvironmentQuery(const EnvironmentSpec& spec, const EnvironmentQuery& q) {
  std::string out = std::to_string(q.distance) + " ";
  appendModule(out, "E", q.params);
  if (spec.followingModule && !q.next.empty()) appendModule(out, q.next, q.nextParams);
  out += '\n';
  appendVector(out, spec.position, q.position);
  appendVector(out, spec.heading, q.heading);
  appendVector(out, spec.left, q.left);
  appendVector(out, spec.up, q.up);
  return out;
}

std::optional<EnvironmentAnswer> parseEnvironmentAnswer(const std::string& line) {
  // cpfg (comm_master.c, LoadCommunicationItem): the distance, then the rest of the line
  // holds E, optionally followed by (v1,v2,...) where an empty value is left unset.
  const char* s = line.c_str();
  while (*s && std::strchr(" ,;:", *s)) ++s;
  if (*s < '0' || *s > '9') return std::nullopt;
  char* end = nullptr;
  EnvironmentAnswer a;
  a.distance = std::strtoull(s, &end, 10);
  const char* e = std::strchr(end, 'E');
  if (!e) return std::nullopt;
  if (e[1] != '(') return a;
  const char* close = std::strchr(e + 2, ')');
  if (!close) return std::nullopt;
  std::string body(e + 2, close);
  size_t b = 0;
  for (;;) {
    const size_t comma = body.find(',', b);
    const std::string item = body.substr(b, comma == std::string::npos ? std::string::npos : comma - b);
    if (item.find_first_not_of(" \t") == std::string::npos) {
      a.params.emplace_back();
    } else {
      char* stop = nullptr;
      const double v = std::strtod(item.c_str(), &stop);
      if (stop == item.c_str() || std::string(stop).find_first_not_of(" \t") != std::string::npos) return std::nullopt;
      a.params.emplace_back(static_cast<float>(v));
    }
    if (comma == std::string::npos) break;
    b = comma + 1;
  }
  return a;
}

// ---------------------------------------------------------------- the program

struct EnvironmentProgram::Impl {
  EnvironmentSpec spec;
  std::string workDir;
  EnvironmentOptions options;
  std::unique_ptr<detail::EnviroChannel> channel;

  void start() { channel = detail::EnviroChannel::start(spec, workDir, options.timeoutSeconds); }
};

EnvironmentProgram::EnvironmentProgram(EnvironmentSpec spec, std::string workDir, EnvironmentOptions options)
    : impl_(std::make_unique<Impl>()) {
  impl_->spec = std::move(spec);
  impl_->workDir = std::move(workDir);
  impl_->options = options;
  impl_->start();
}

EnvironmentProgram::~EnvironmentProgram() = default;

const std::string& EnvironmentProgram::name() const { return impl_->spec.command.front(); }

void EnvironmentProgram::restart() {
  impl_->channel.reset();  // ends and reaps the program
  impl_->start();
}

std::vector<EnvironmentAnswer> EnvironmentProgram::exchange(const std::vector<EnvironmentQuery>& queries, int step) {
  std::vector<EnvironmentAnswer> answers;
  if (queries.empty()) return answers;
  detail::EnviroChannel& ch = *impl_->channel;
  // cpfg's chunks (comm_master.c, SendDataItem): when an item does not fit, the chunk ends
  // with `Control: flag 0` (flag 1 for the first chunk, 0 after), the program answers it,
  // and the next chunk starts; the last ends with `Control: flag step` (4, or 5 alone).
  auto collect = [&] {
    for (std::string line; ch.readAnswer(line);) {
      std::optional<EnvironmentAnswer> a = parseEnvironmentAnswer(line);
      if (!a) ch.fail("sent a malformed answer '" + line.substr(0, 80) + "' (expected 'distance E(values)')");
      answers.push_back(std::move(*a));
    }
  };
  int flag = detail::kFirstChunk | detail::kLastChunk;
  ch.beginChunk();
  for (const EnvironmentQuery& q : queries) {
    const std::string item = formatEnvironmentQuery(impl_->spec, q);
    if (!ch.fits(item)) {
      ch.endChunk(flag & ~detail::kLastChunk, 0);
      collect();
      flag = detail::kLastChunk;
      ch.beginChunk();
    }
    ch.append(item);
  }
  ch.endChunk(flag, step);
  collect();
  return answers;
}

}  // namespace sprig::lsystem
