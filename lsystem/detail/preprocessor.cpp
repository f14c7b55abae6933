// cpfg's C preprocessor, as cpfg runs it on an L-system file before reading it: `#define`
// of module strings and function-like macros, `#undef`, `#include "file"` of files in the
// object's folder, `#ifdef`/`#ifndef`/`#else`/`#endif`. Part of the Scanner (it produces
// the scanner's lines and remembers where each column was written, so that every error
// points at the user's file:line:col). docs/GRAMMAR.md, "The C preprocessor".

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "lsystem/detail/scanner.h"

namespace sprig::lsystem::detail {

namespace {

/// Files included inside each other deeper than this are an error (a cycle, most likely).
constexpr int kMaxIncludeDepth = 16;
/// Macro expansions nested deeper than this are an error.
constexpr int kMaxExpansionDepth = 64;

std::string trimmed(const std::string& s, size_t b) {
  size_t e = s.size();
  while (b < e && isSpace(s[b])) ++b;
  while (e > b && isSpace(s[e - 1])) --e;
  return s.substr(b, e - b);
}

/// End of the pp-number or identifier starting at i of s.
size_t tokenEnd(const std::string& s, size_t i) {
  if (std::isdigit(static_cast<unsigned char>(s[i])) || (s[i] == '.' && i + 1 < s.size() && std::isdigit(static_cast<unsigned char>(s[i + 1])))) {
    ++i;
    while (i < s.size()) {
      char c = s[i];
      if ((c == '+' || c == '-') && (s[i - 1] == 'e' || s[i - 1] == 'E')) ++i;
      else if (isIdentChar(c) || c == '.') ++i;
      else break;
    }
    return i;
  }
  while (i < s.size() && isIdentChar(s[i])) ++i;
  return i;
}

/// cpp's `#if` arithmetic over a text with every name already replaced: numbers, `( )`,
/// unary `! - +`, `* / %`, `+ -`, `< <= > >=`, `== !=`, `&&`, `||`. A name left over is 0,
/// as in C. nullopt when the text is no such expression.
class PpCondition {
 public:
  explicit PpCondition(const std::string& t) : t_(t) {}
  std::optional<double> value() {
    std::optional<double> v = orExpr();
    skip();
    return v && i_ == t_.size() ? v : std::nullopt;
  }

 private:
  const std::string& t_;
  size_t i_ = 0;
  void skip() {
    while (i_ < t_.size() && isSpace(t_[i_])) ++i_;
  }
  bool eat(const char* op) {
    skip();
    const size_t n = std::char_traits<char>::length(op);
    if (t_.compare(i_, n, op) != 0) return false;
    // `<` is not the start of `<=`, `!` not of `!=`, `=` never alone
    if (n == 1 && i_ + 1 < t_.size() && t_[i_ + 1] == '=' && std::strchr("<>!=", op[0])) return false;
    if (n == 1 && i_ + 1 < t_.size() && t_[i_ + 1] == op[0] && std::strchr("&|", op[0])) return false;
    i_ += n;
    return true;
  }
  template <typename Next, typename Apply>
  std::optional<double> binary(Next next, std::initializer_list<const char*> ops, Apply apply) {
    std::optional<double> a = (this->*next)();
    for (;;) {
      const char* hit = nullptr;
      for (const char* op : ops)
        if (!hit && eat(op)) hit = op;
      if (!hit) return a;
      std::optional<double> b = (this->*next)();
      if (!a || !b) return std::nullopt;
      a = apply(std::string(hit), *a, *b);
      if (!a) return std::nullopt;
    }
  }
  std::optional<double> orExpr() {
    return binary(&PpCondition::andExpr, {"||"}, [](const std::string&, double a, double b) -> std::optional<double> { return (a != 0 || b != 0) ? 1.0 : 0.0; });
  }
  std::optional<double> andExpr() {
    return binary(&PpCondition::eqExpr, {"&&"}, [](const std::string&, double a, double b) -> std::optional<double> { return (a != 0 && b != 0) ? 1.0 : 0.0; });
  }
  std::optional<double> eqExpr() {
    return binary(&PpCondition::relExpr, {"==", "!="}, [](const std::string& op, double a, double b) -> std::optional<double> {
      return (op == "==") == (a == b) ? 1.0 : 0.0;
    });
  }
  std::optional<double> relExpr() {
    return binary(&PpCondition::addExpr, {"<=", ">=", "<", ">"}, [](const std::string& op, double a, double b) -> std::optional<double> {
      const bool r = op == "<=" ? a <= b : op == ">=" ? a >= b : op == "<" ? a < b : a > b;
      return r ? 1.0 : 0.0;
    });
  }
  std::optional<double> addExpr() {
    return binary(&PpCondition::mulExpr, {"+", "-"}, [](const std::string& op, double a, double b) -> std::optional<double> {
      return op == "+" ? a + b : a - b;
    });
  }
  std::optional<double> mulExpr() {
    return binary(&PpCondition::unary, {"*", "/", "%"}, [](const std::string& op, double a, double b) -> std::optional<double> {
      if (op != "*" && b == 0) return std::nullopt;
      return op == "*" ? a * b : op == "/" ? a / b : std::fmod(a, b);
    });
  }
  std::optional<double> unary() {
    if (eat("!")) {
      std::optional<double> v = unary();
      return v ? std::optional<double>(*v == 0 ? 1.0 : 0.0) : std::nullopt;
    }
    if (eat("-")) {
      std::optional<double> v = unary();
      return v ? std::optional<double>(-*v) : std::nullopt;
    }
    if (eat("+")) return unary();
    skip();
    if (eat("(")) {
      std::optional<double> v = orExpr();
      return eat(")") ? v : std::nullopt;
    }
    if (i_ < t_.size() && (isIdentStart(t_[i_]) || std::isdigit(static_cast<unsigned char>(t_[i_])) || t_[i_] == '.')) {
      const size_t e = tokenEnd(t_, i_);
      const std::string tok = t_.substr(i_, e - i_);
      i_ = e;
      if (isIdentStart(tok[0])) return 0.0;
      char* end = nullptr;
      const double v = std::strtod(tok.c_str(), &end);
      return end && (*end == '\0' || std::strchr("uUlL", *end)) ? std::optional<double>(v) : std::nullopt;
    }
    return std::nullopt;
  }
};

}  // namespace

/// True when a `#define` body is a constant the grammar parser reads as a value (and `-D`
/// may override). cpfg's notation: a number, or one expression in parentheses over
/// numbers, earlier constants and functions: substituting such a body as cpp does gives
/// the same value, so reading it as a value changes nothing. Sprig's notation keeps its
/// constants as values (`#define b a*10`, ABOP as printed): every body but a module string.
static bool isConstantBody(const std::string& body, const std::vector<std::pair<std::string, int>>& constants,
                           Dialect dialect) {
  if (dialect == Dialect::Sprig)
    return body.find_first_of("[]$@{}~") == std::string::npos &&
           (body.find('?') == std::string::npos || body.find(':') != std::string::npos);
  if (body.empty()) return false;
  char* end = nullptr;
  std::strtod(body.c_str(), &end);
  if (end && *end == '\0') return true;
  if (body.front() != '(' || body.back() != ')') return false;
  int depth = 0;
  for (size_t i = 0; i < body.size(); ++i) {
    depth += body[i] == '(' ? 1 : body[i] == ')' ? -1 : 0;
    if (depth == 0 && i + 1 < body.size()) return false;  // `(a) + (b)`: not one parenthesized unit
  }
  if (body.find_first_of("[]$@{}~\"") != std::string::npos) return false;
  for (size_t i = 0; i < body.size();) {
    if (!isIdentStart(body[i]) && !std::isdigit(static_cast<unsigned char>(body[i]))) {
      ++i;
      continue;
    }
    size_t e = tokenEnd(body, i);
    if (isIdentStart(body[i])) {
      std::string id = body.substr(i, e - i);
      size_t k = e;
      while (k < body.size() && isSpace(body[k])) ++k;
      bool call = k < body.size() && body[k] == '(';
      bool known = std::any_of(constants.begin(), constants.end(), [&](const auto& c) { return c.first == id; });
      if (!call && !known) return false;
    }
    i = e;
  }
  return true;
}

std::string Scanner::expandText(const std::string& text, std::vector<std::string>& disabled, int depth, bool& failed) {
  if (depth > kMaxExpansionDepth) {
    failed = true;
    return text;
  }
  std::string out;
  size_t i = 0;
  while (i < text.size()) {
    char c = text[i];
    if (c == '"') {  // a string literal (printf's format) is copied as it is
      size_t e = text.find('"', i + 1);
      e = e == std::string::npos ? text.size() : e + 1;
      out.append(text, i, e - i);
      i = e;
      continue;
    }
    if (!isIdentStart(c) && !std::isdigit(static_cast<unsigned char>(c)) && !(c == '.' && i + 1 < text.size() && std::isdigit(static_cast<unsigned char>(text[i + 1])))) {
      out += c;
      ++i;
      continue;
    }
    size_t e = tokenEnd(text, i);
    std::string id = text.substr(i, e - i);
    auto it = std::find_if(macros_.begin(), macros_.end(), [&](const auto& m) { return m.first == id; });
    if (!isIdentStart(c) || it == macros_.end() || std::find(disabled.begin(), disabled.end(), id) != disabled.end()) {
      out += id;
      i = e;
      continue;
    }
    const Macro& m = it->second;
    std::string body = m.body;
    if (m.functionLike) {
      size_t k = e;
      while (k < text.size() && isSpace(text[k])) ++k;
      if (k >= text.size() || text[k] != '(') {  // the name without arguments is not a call
        out += id;
        i = e;
        continue;
      }
      std::vector<std::string> args(1);
      int level = 0;
      size_t j = k + 1;
      for (; j < text.size(); ++j) {
        char d = text[j];
        if (d == '(') ++level;
        if (d == ')' && level-- == 0) break;
        if (d == ',' && level == 0) args.emplace_back();
        else args.back() += d;
      }
      if (j >= text.size()) {
        failed = true;
        return text;
      }
      for (std::string& a : args) a = trimmed(a, 0);
      if (args.size() == 1 && args[0].empty() && m.params.empty()) args.clear();
      if (args.size() != m.params.size()) {
        failed = true;
        return text;
      }
      // Parameters replaced token by token.
      std::string sub;
      for (size_t p = 0; p < m.body.size();) {
        if (isIdentStart(m.body[p])) {
          size_t q = tokenEnd(m.body, p);
          std::string name = m.body.substr(p, q - p);
          auto pi = std::find(m.params.begin(), m.params.end(), name);
          sub += pi == m.params.end() ? name : args[static_cast<size_t>(pi - m.params.begin())];
          p = q;
        } else if (std::isdigit(static_cast<unsigned char>(m.body[p]))) {
          size_t q = tokenEnd(m.body, p);
          sub.append(m.body, p, q - p);
          p = q;
        } else {
          sub += m.body[p++];
        }
      }
      body = sub;
      e = j + 1;
    }
    disabled.push_back(id);
    out += expandText(body, disabled, depth + 1, failed);
    disabled.pop_back();
    i = e;
  }
  return out;
}

std::string Scanner::expand(const std::string& line, std::vector<int>& map, int file, int lineNo, const std::string& rawLine) {
  map.clear();
  if (macros_.empty()) return line;
  std::string out;
  bool changed = false;
  size_t i = 0;
  while (i < line.size()) {
    char c = line[i];
    if (!isIdentStart(c)) {
      size_t e = (std::isdigit(static_cast<unsigned char>(c)) || c == '.') ? std::max(tokenEnd(line, i), i + 1) : i + 1;
      for (size_t k = i; k < e; ++k) {
        out += line[k];
        map.push_back(static_cast<int>(k));
      }
      i = e;
      continue;
    }
    size_t e = tokenEnd(line, i);
    std::string id = line.substr(i, e - i);
    auto it = std::find_if(macros_.begin(), macros_.end(), [&](const auto& m) { return m.first == id; });
    size_t callEnd = e;
    if (it != macros_.end() && it->second.functionLike) {
      size_t k = e;
      while (k < line.size() && isSpace(line[k])) ++k;
      if (k < line.size() && line[k] == '(') {
        int level = 0;
        size_t j = k + 1;
        for (; j < line.size(); ++j) {
          if (line[j] == '(') ++level;
          if (line[j] == ')' && level-- == 0) break;
        }
        if (j >= line.size()) {
          diags_.error(SourceLoc{files_[file], lineNo, static_cast<int>(i) + 1},
                       "unclosed '(' in the call of macro '" + id + "'", rawLine);
          map.clear();
          return line;
        }
        callEnd = j + 1;
      } else {
        it = macros_.end();  // a function-like macro's name alone is not expanded
      }
    }
    if (it == macros_.end()) {
      for (size_t k = i; k < e; ++k) {
        out += line[k];
        map.push_back(static_cast<int>(k));
      }
      i = e;
      continue;
    }
    std::vector<std::string> disabled;
    bool failed = false;
    std::string text = expandText(line.substr(i, callEnd - i), disabled, 0, failed);
    if (failed) {
      const Macro& m = it->second;
      diags_.error(SourceLoc{files_[file], lineNo, static_cast<int>(i) + 1},
                   m.functionLike ? "macro '" + id + "' takes " + std::to_string(m.params.size()) +
                                        " argument(s) (defined at " + files_[m.file] + ":" + std::to_string(m.line) +
                                        "), or its expansion nests deeper than " + std::to_string(kMaxExpansionDepth) + " levels"
                                  : "the expansion of macro '" + id + "' nests deeper than " + std::to_string(kMaxExpansionDepth) + " levels",
                   rawLine);
      map.clear();
      return line;
    }
    out += text;
    map.insert(map.end(), text.size(), static_cast<int>(i));
    changed = true;
    i = callEnd;
  }
  if (!changed) map.clear();
  return out;
}

namespace {

/// cpp's line splicing: a directive whose line ends in a backslash goes on with the next line
/// (`#define LEAF [+F \` then the rest); the lines it takes stay blank. Returns line k of
/// clean with its continuations joined, and sets joinedUntil to the last line taken (k when
/// the line does not continue).
std::string spliceDirective(const std::vector<std::string>& clean, size_t k, size_t& joinedUntil) {
  auto continues = [](const std::string& t) {
    size_t e = t.size();
    while (e > 0 && isSpace(t[e - 1])) --e;
    return e > 0 && t[e - 1] == '\\' ? e : std::string::npos;
  };
  size_t j = k, cut = continues(clean[k]);
  std::string joined = clean[k];
  while (cut != std::string::npos && j + 1 < clean.size()) {
    joined.resize(cut - 1);
    joined += ' ';
    joined += clean[++j];
    cut = continues(joined);
  }
  if (cut != std::string::npos) joined.resize(cut - 1);
  joinedUntil = j;
  return joined;
}

}  // namespace

/// One directive line being read: where it is, its text and its first two words.
struct Scanner::Directive {
  int file;
  size_t k;               ///< 0-based line in the file
  const std::string& s;   ///< the line (continuations joined)
  const std::string& raw; ///< the line as written
  size_t hash;            ///< the '#' column
  std::string word, name; ///< `define`, `LEAF`
  size_t nameStart, nameEnd;
  int depth;              ///< of #include
  size_t openAtStart;     ///< conditionals open when the file began
};

void Scanner::emitLine(int file, size_t k, const std::string& raw, std::string text, std::vector<int> map) {
  raw_.push_back(raw);
  clean_.push_back(std::move(text));
  origin_.push_back(Origin{file, static_cast<int>(k) + 1});
  colMap_.push_back(std::move(map));
}

void Scanner::directiveError(const Directive& d, size_t col, const std::string& msg) {
  diags_.error(SourceLoc{files_[d.file], static_cast<int>(d.k) + 1, static_cast<int>(col) + 1}, msg, d.raw);
}

bool Scanner::preprocessorActive() const { return conditionals_.empty() || conditionals_.back().active; }

bool Scanner::conditionalDirective(const Directive& d) {
  const std::string& word = d.word;
  const Conditional opened{preprocessorActive(), preprocessorActive(), false, d.file, static_cast<int>(d.k) + 1, static_cast<int>(d.hash)};
  if (word == "ifdef" || word == "ifndef") {
    if (d.name.empty() || !isIdentStart(d.name[0])) directiveError(d, d.nameStart, "expected a name after '#" + word + "'");
    const bool defined = std::any_of(macros_.begin(), macros_.end(), [&](const auto& m) { return m.first == d.name; }) ||
                         std::any_of(constants_.begin(), constants_.end(), [&](const auto& c) { return c.first == d.name; });
    Conditional c = opened;
    c.active = preprocessorActive() && (defined == (word == "ifdef"));
    conditionals_.push_back(c);
    emitLine(d.file, d.k, d.raw, "", {});
    return true;
  }
  if (word == "if") {
    Conditional c = opened;
    if (preprocessorActive()) {
      const size_t at = d.s.find("if", d.hash) + 2;
      std::optional<double> v = ifCondition(d.s.substr(at));
      if (!v) directiveError(d, at, "cannot evaluate '#if" + d.s.substr(at) + "' (expected a constant expression of numbers and #define names)");
      c.active = v && *v != 0;
    }
    conditionals_.push_back(c);
    emitLine(d.file, d.k, d.raw, "", {});
    return true;
  }
  if (word != "else" && word != "endif") return false;
  if (conditionals_.size() <= d.openAtStart) {
    directiveError(d, d.hash, "'#" + word + "' without '#ifdef' or '#ifndef'");
  } else if (word == "endif") {
    conditionals_.pop_back();
  } else if (conditionals_.back().elseSeen) {
    directiveError(d, d.hash, "a second '#else' for the '#if' at line " + std::to_string(conditionals_.back().line));
  } else {
    Conditional& c = conditionals_.back();
    c.elseSeen = true;
    c.active = c.parentActive && !c.active;
  }
  emitLine(d.file, d.k, d.raw, "", {});
  return true;
}

std::optional<double> Scanner::ifCondition(const std::string& text) {
  // defined(NAME) and defined NAME first, then the macros, then the constants' bodies
  // (the file's values: -D does not change which lines #if keeps), repeatedly.
  auto isDefined = [&](const std::string& n) {
    return std::any_of(macros_.begin(), macros_.end(), [&](const auto& m) { return m.first == n; }) ||
           std::any_of(constants_.begin(), constants_.end(), [&](const auto& c) { return c.first == n; });
  };
  std::string t;
  for (size_t i = 0; i < text.size();) {
    if (!isIdentStart(text[i]) || text.compare(i, 7, "defined") != 0 || tokenEnd(text, i) != i + 7) {
      const size_t e = isIdentStart(text[i]) || std::isdigit(static_cast<unsigned char>(text[i])) ? tokenEnd(text, i) : i + 1;
      t.append(text, i, e - i);
      i = e;
      continue;
    }
    size_t k = i + 7;
    while (k < text.size() && isSpace(text[k])) ++k;
    const bool paren = k < text.size() && text[k] == '(';
    if (paren) ++k;
    while (k < text.size() && isSpace(text[k])) ++k;
    const size_t e = k < text.size() && isIdentStart(text[k]) ? tokenEnd(text, k) : k;
    t += isDefined(text.substr(k, e - k)) ? "1" : "0";
    k = e;
    while (paren && k < text.size() && isSpace(text[k])) ++k;
    i = paren && k < text.size() && text[k] == ')' ? k + 1 : k;
  }
  std::vector<std::string> disabled;
  bool failed = false;
  t = expandText(t, disabled, 0, failed);
  if (failed) return std::nullopt;
  for (int round = 0; round < kMaxExpansionDepth; ++round) {
    std::string out;
    bool changed = false;
    for (size_t i = 0; i < t.size();) {
      if (!isIdentStart(t[i]) && !std::isdigit(static_cast<unsigned char>(t[i]))) {
        out += t[i++];
        continue;
      }
      const size_t e = tokenEnd(t, i);
      auto body = std::find_if(constantBodies_.begin(), constantBodies_.end(), [&](const auto& c) { return c.first == t.substr(i, e - i); });
      if (isIdentStart(t[i]) && body != constantBodies_.end()) {
        out += "(" + body->second + ")";
        changed = true;
      } else {
        out.append(t, i, e - i);
      }
      i = e;
    }
    t = out;
    if (!changed) return PpCondition(t).value();
  }
  return std::nullopt;
}

void Scanner::defineDirective(const Directive& d) {
  const std::string& s = d.s;
  const std::string& name = d.name;
  const size_t ne = d.nameEnd;
  Macro m;
  m.file = d.file;
  m.line = static_cast<int>(d.k) + 1;
  size_t after = ne;
  if (ne < s.size() && s[ne] == '(') {  // function-like: the '(' right after the name
    size_t close = s.find(')', ne);
    if (close == std::string::npos) {
      directiveError(d, ne, "unclosed '(' in '#define " + name + "('");
      emitLine(d.file, d.k, d.raw, "", {});
      return;
    }
    std::string list = s.substr(ne + 1, close - ne - 1);
    size_t p = 0;
    while (p <= list.size()) {
      size_t c = list.find(',', p);
      if (c == std::string::npos) c = list.size();
      std::string param = trimmed(list.substr(p, c - p), 0);
      if (!param.empty() || c < list.size()) {
        if (param.empty() || !isIdentStart(param[0]) || tokenEnd(param, 0) != param.size())
          directiveError(d, ne + 1 + p, "invalid parameter name '" + param + "' in '#define " + name + "(...)'");
        m.params.push_back(param);
      }
      p = c + 1;
    }
    m.functionLike = true;
    after = close + 1;
  }
  m.body = trimmed(s, after);
  if (!m.functionLike && isConstantBody(m.body, constants_, dialect_)) {
    constants_.emplace_back(name, static_cast<int>(d.k) + 1);
    constantBodies_.emplace_back(name, m.body);
    emitLine(d.file, d.k, d.raw, s, {});  // read by the grammar parser (a value -D may override)
    return;
  }
  auto prev = std::find_if(macros_.begin(), macros_.end(), [&](const auto& e) { return e.first == name; });
  if (prev != macros_.end() || std::any_of(constants_.begin(), constants_.end(), [&](const auto& c) { return c.first == name; })) {
    directiveError(d, d.nameStart, "'" + name + "' is already defined" +
                                       (prev != macros_.end() ? " at " + files_[prev->second.file] + ":" + std::to_string(prev->second.line) : ""));
  } else {
    macros_.emplace_back(name, std::move(m));
  }
  emitLine(d.file, d.k, d.raw, "", {});
}

void Scanner::includeDirective(const Directive& d) {
  const std::string& s = d.s;
  const size_t ni = d.nameStart;
  emitLine(d.file, d.k, d.raw, "", {});
  char open = ni < s.size() ? s[ni] : '\0';
  char closeCh = open == '"' ? '"' : open == '<' ? '>' : '\0';
  size_t close = closeCh ? s.find(closeCh, ni + 1) : std::string::npos;
  if (close == std::string::npos) {
    directiveError(d, ni, "expected a file name in quotes after '#include'");
    return;
  }
  const std::string target = s.substr(ni + 1, close - ni - 1);
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path top = fs::path(fileName_).parent_path();
  fs::path root = fs::weakly_canonical(fs::absolute(top.empty() ? fs::path(".") : top, ec), ec);
  fs::path from = fs::path(files_[d.file]).parent_path();
  fs::path path = fs::weakly_canonical(fs::absolute(from / target, ec), ec);
  fs::path rel = path.lexically_relative(root);
  if (fs::path(target).is_absolute() || rel.empty() || *rel.begin() == "..") {
    directiveError(d, ni, "'#include \"" + target + "\"' is outside the object's folder: only files beside the L-system "
                          "(or in folders below it) may be included");
    return;
  }
  if (d.depth + 1 > kMaxIncludeDepth) {
    directiveError(d, ni, "'#include' nested deeper than " + std::to_string(kMaxIncludeDepth) + " files (does a file include itself?)");
    return;
  }
  std::string text;
  try {
    text = readFile(path);
  } catch (const FileReadError& e) {
    directiveError(d, ni, FileReadError(from / target, e.reason()).what());  // the name as written, not the canonical one
    return;
  }
  files_.push_back((from / target).lexically_normal().string());
  const int index = static_cast<int>(files_.size()) - 1;
  std::pair<int, int> pending{0, 0};
  std::string cleanText = blankComments(text, pending);
  if (pending.first) diags_.error(SourceLoc{files_[index], pending.first, pending.second + 1}, "unterminated comment '/*'");
  preprocess(index, splitAtNewlines(text), splitAtNewlines(cleanText), d.depth + 1);
}

void Scanner::directive(const Directive& d) {
  if (conditionalDirective(d)) return;
  if (!preprocessorActive()) {
    emitLine(d.file, d.k, d.raw, "", {});
    return;
  }
  if (d.word == "define" && !d.name.empty() && isIdentStart(d.name[0])) {
    defineDirective(d);
  } else if (d.word == "undef") {
    macros_.erase(std::remove_if(macros_.begin(), macros_.end(), [&](const auto& e) { return e.first == d.name; }), macros_.end());
    constants_.erase(std::remove_if(constants_.begin(), constants_.end(), [&](const auto& e) { return e.first == d.name; }), constants_.end());
    constantBodies_.erase(std::remove_if(constantBodies_.begin(), constantBodies_.end(), [&](const auto& e) { return e.first == d.name; }),
                          constantBodies_.end());
    emitLine(d.file, d.k, d.raw, "", {});
  } else if (d.word == "include") {
    includeDirective(d);
  } else {
    emitLine(d.file, d.k, d.raw, d.s, {});  // `#define` without a name and other directives: the grammar parser reports them
  }
}

void Scanner::preprocess(int file, const std::vector<std::string>& raw, const std::vector<std::string>& clean, int depth) {
  const size_t openAtStart = conditionals_.size();
  size_t joinedUntil = 0;  // the last line a directive's backslash continuation took
  for (size_t k = 0; k < clean.size(); ++k) {
    if (k > 0 && k <= joinedUntil) {  // part of the directive above: blank here
      emitLine(file, k, raw[k], "", {});
      continue;
    }
    const size_t b = static_cast<size_t>(firstNonSpace(clean[k]));
    if (b < clean[k].size() && clean[k][b] == '#') {
      const std::string s = spliceDirective(clean, k, joinedUntil);
      size_t i = b + 1;
      while (i < s.size() && isSpace(s[i])) ++i;
      size_t we = i;
      while (we < s.size() && isIdentChar(s[we])) ++we;
      size_t ni = we;
      while (ni < s.size() && isSpace(s[ni])) ++ni;
      size_t ne = ni;
      while (ne < s.size() && isIdentChar(s[ne])) ++ne;
      directive(Directive{file, k, s, raw[k], b, s.substr(i, we - i), s.substr(ni, ne - ni), ni, ne, depth, openAtStart});
      continue;
    }
    if (!preprocessorActive()) {
      emitLine(file, k, raw[k], "", {});
      continue;
    }
    std::vector<int> map;
    std::string text = expand(clean[k], map, file, static_cast<int>(k) + 1, raw[k]);
    emitLine(file, k, raw[k], std::move(text), std::move(map));
  }
  if (depth > 0) {
    // An '#ifdef' left open at the end of an included file.
    while (conditionals_.size() > openAtStart) {
      const Conditional& c = conditionals_.back();
      diags_.error(SourceLoc{files_[c.file], c.line, c.col + 1}, "'#if' block without '#endif'");
      conditionals_.pop_back();
    }
  }
}

}  // namespace sprig::lsystem::detail
