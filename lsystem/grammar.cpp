#include "lsystem/grammar.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <unordered_map>

#include "core/atomic_file.h"
#include "core/rng.h"
#include "lsystem/detail/program.h"

namespace sprig::lsystem {

using detail::Arg;
using detail::ArgKind;
using detail::CodeRange;
using detail::Instr;
using detail::Op;
using detail::PatternItem;
using detail::Production;
using detail::Program;
using detail::RuleSet;
using detail::SuccModule;

namespace {

/// Stream id for random draws in axiom parameters.
constexpr uint64_t kAxiomStream = 0xfffffffffffffff1ull;

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
bool isIdentStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool isIdentChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

/// A span [b, e) of one line (0-based offsets into the cleaned line).
struct Span {
  int line = 0;  ///< 1-based
  int b = 0;
  int e = 0;
};

/// One module as written: its name and, per argument, the span of the argument text.
struct RawModule {
  std::string name;
  int col = 0;  ///< 0-based offset of the name
  std::vector<Span> args;
  bool hasParens = false;
};

/// Thrown inside the expression parser; already reported.
struct ExprFail {};

struct FunctionInfo {
  const char* name;
  Op op;
  int arity;
};

constexpr FunctionInfo kFunctions[] = {
    {"sin", Op::Sin, 1},     {"cos", Op::Cos, 1},     {"tan", Op::Tan, 1},     {"asin", Op::Asin, 1},
    {"acos", Op::Acos, 1},   {"atan", Op::Atan, 1},   {"atan2", Op::Atan2, 2}, {"sqrt", Op::Sqrt, 1},
    {"exp", Op::Exp, 1},     {"log", Op::Log, 1},     {"pow", Op::PowFn, 2},   {"abs", Op::Abs, 1},
    {"min", Op::Min, 2},     {"max", Op::Max, 2},     {"floor", Op::Floor, 1}, {"ceil", Op::Ceil, 1},
    {"sign", Op::Sign, 1},   {"ran", Op::Ran, 1},     {"nran", Op::Nran, 2},
};

const char* const kHeaders[] = {"lsystem", "derivation length", "seed", "angle", "axiom", "ignore", "consider",
                                "decomposition", "interpretation", "homomorphism", "maximum depth", "endlsystem"};

int arityOf(Op op) {
  switch (op) {
    case Op::Const: case Op::Var: return 0;
    case Op::Neg: case Op::Not: case Op::Sin: case Op::Cos: case Op::Tan: case Op::Asin: case Op::Acos:
    case Op::Atan: case Op::Sqrt: case Op::Exp: case Op::Log: case Op::Abs: case Op::Floor: case Op::Ceil:
    case Op::Sign: case Op::Ran:
      return 1;
    default: return 2;
  }
}

std::string formatNumber(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

enum class Block { Main, Decomposition, Interpretation };

class Parser {
 public:
  Parser(std::string_view text, const std::string& fileName, const GrammarOverrides& overrides)
      : text_(text), overrides_(overrides) {
    prog_.fileName = fileName;
    for (const char* s : kTurtleSymbols) prog_.symbols.intern(s);
    prog_.openBracket = static_cast<SymbolId>(prog_.symbols.find("["));
    prog_.closeBracket = static_cast<SymbolId>(prog_.symbols.find("]"));
    prog_.cut = static_cast<SymbolId>(prog_.symbols.find("%"));
    for (const char* s : kTurtleSymbols)
      if (std::string_view(s).size() > 1) multiNames_.emplace_back(s);
  }

  std::shared_ptr<Program> run() {
    splitLines();
    firstPass();
    secondPass();
    // Only on an otherwise clean file: a successor that failed to parse wrote nothing, and
    // its modules' parameter counts would be missed.
    if (!diags_.hasErrors()) checkArities();
    finish();
    diags_.throwIfErrors();
    return std::make_shared<Program>(std::move(prog_));
  }

  // ---- module-string tokenizing (also used by parseModuleString) ----------------------

  /// Splits clean_[line][b,e) into modules. Reports errors; returns false on error.
  bool tokenizeModules(int line, int b, int e, std::vector<RawModule>& out) {
    const std::string& s = clean_[line - 1];
    int i = b;
    bool ok = true;
    while (i < e) {
      if (isSpace(s[i])) { ++i; continue; }
      char c = s[i];
      if (c == '(' || c == ')' || c == ',') {
        error(line, i, c == ')' ? "unmatched ')'" : std::string("unexpected '") + c + "' (parameters must follow a module name)");
        return false;
      }
      RawModule m;
      m.col = i;
      size_t best = 0;
      for (const std::string& name : multiNames_)
        if (name.size() > best && static_cast<int>(name.size()) <= e - i && s.compare(i, name.size(), name) == 0) best = name.size();
      if (best) {
        m.name = s.substr(i, best);
        i += static_cast<int>(best);
      } else if (c == '~' && i + 1 < e && std::isalpha(static_cast<unsigned char>(s[i + 1]))) {
        m.name = s.substr(i, 2);
        i += 2;
      } else {
        m.name = std::string(1, c);
        ++i;
      }
      int j = i;
      while (j < e && isSpace(s[j])) ++j;
      if (j < e && s[j] == '(') {
        m.hasParens = true;
        int depth = 0;
        int argStart = j + 1;
        int k = j;
        for (; k < e; ++k) {
          if (s[k] == '(') ++depth;
          else if (s[k] == ')') {
            if (--depth == 0) break;
          } else if (s[k] == ',' && depth == 1) {
            m.args.push_back({line, argStart, k});
            argStart = k + 1;
          }
        }
        if (k >= e) {
          error(line, j, "missing ')' after the parameters of '" + m.name + "'");
          return false;
        }
        m.args.push_back({line, argStart, k});
        if (m.args.size() == 1 && trim(m.args[0]).b == trim(m.args[0]).e) m.args.clear();  // `F()`
        else
          for (const Span& a : m.args)
            if (trim(a).b == trim(a).e) {
              error(line, a.b, "empty parameter in '" + m.name + "'");
              ok = false;
            }
        i = k + 1;
      }
      out.push_back(std::move(m));
    }
    return ok;
  }

  Span trim(Span sp) const {
    const std::string& s = clean_[sp.line - 1];
    while (sp.b < sp.e && isSpace(s[sp.b])) ++sp.b;
    while (sp.e > sp.b && isSpace(s[sp.e - 1])) --sp.e;
    return sp;
  }

  std::string_view view(Span sp) const { return std::string_view(clean_[sp.line - 1]).substr(sp.b, sp.e - sp.b); }

  void error(int line, int col0, std::string msg) {
    diags_.error(SourceLoc{prog_.fileName, line, col0 + 1}, std::move(msg), line >= 1 && line <= static_cast<int>(raw_.size()) ? raw_[line - 1] : "");
  }

  /// Loads text as a single line for parseModuleString.
  void loadSingle(std::string_view text, SymbolTable& symbols) {
    text_ = text;
    splitLines();
    prog_.symbols = symbols;
    multiNames_.clear();
    for (size_t i = 0; i < symbols.size(); ++i)
      if (symbols.name(static_cast<SymbolId>(i)).size() > 1 && symbols.name(static_cast<SymbolId>(i))[0] != '~')
        multiNames_.push_back(symbols.name(static_cast<SymbolId>(i)));
  }

  /// Tokenizes every line of a loaded text as a constant module string.
  ModuleString constantString(SymbolTable& symbols) {
    ModuleString out;
    for (int line = 1; line <= static_cast<int>(clean_.size()); ++line) {
      std::vector<RawModule> mods;
      if (!tokenizeModules(line, 0, static_cast<int>(clean_[line - 1].size()), mods)) continue;
      appendConstant(mods, line, out, nullptr);
    }
    diags_.throwIfErrors();
    symbols = prog_.symbols;
    return out;
  }

 private:
  // ---- lines and comments ---------------------------------------------------------------

  void splitLines() {
    std::string clean(text_);
    size_t i = 0;
    int line = 1;
    size_t lineStart = 0;
    while (i < clean.size()) {
      char c = clean[i];
      if (c == '\n') {
        ++line;
        lineStart = i + 1;
        ++i;
      } else if (c == '/' && i + 1 < clean.size() && clean[i + 1] == '/') {
        while (i < clean.size() && clean[i] != '\n') clean[i++] = ' ';
      } else if (c == '/' && i + 1 < clean.size() && clean[i + 1] == '*') {
        int startLine = line;
        int startCol = static_cast<int>(i - lineStart);
        clean[i] = clean[i + 1] = ' ';
        i += 2;
        bool closed = false;
        while (i < clean.size()) {
          if (clean[i] == '*' && i + 1 < clean.size() && clean[i + 1] == '/') {
            clean[i] = clean[i + 1] = ' ';
            i += 2;
            closed = true;
            break;
          }
          if (clean[i] == '\n') {
            ++line;
            lineStart = i + 1;
          } else {
            clean[i] = ' ';
          }
          ++i;
        }
        if (!closed) pendingComment_ = {startLine, startCol};
      } else {
        ++i;
      }
    }
    auto split = [](const std::string& s) {
      std::vector<std::string> lines;
      size_t start = 0;
      for (;;) {
        size_t nl = s.find('\n', start);
        std::string l = s.substr(start, nl == std::string::npos ? std::string::npos : nl - start);
        if (!l.empty() && l.back() == '\r') l.pop_back();
        lines.push_back(std::move(l));
        if (nl == std::string::npos) break;
        start = nl + 1;
      }
      return lines;
    };
    clean_ = split(clean);
    raw_ = split(std::string(text_));
  }

  // ---- line classification ----------------------------------------------------------------

  struct Header {
    std::string key;  ///< lower-cased, single-spaced
    int valueBegin = 0;
  };

  /// `key:` at the start of a line (letters and spaces before a colon), if any.
  std::optional<Header> headerOf(const std::string& s, int b) const {
    int i = b;
    std::string key;
    while (i < static_cast<int>(s.size()) && (std::isalpha(static_cast<unsigned char>(s[i])) || s[i] == ' ' || s[i] == '\t')) {
      char c = static_cast<char>(std::tolower(static_cast<unsigned char>(s[i])));
      if (isSpace(c)) {
        if (!key.empty() && key.back() != ' ') key += ' ';
      } else {
        key += c;
      }
      ++i;
    }
    if (i >= static_cast<int>(s.size()) || s[i] != ':' || key.empty()) return std::nullopt;
    if (key.back() == ' ') key.pop_back();
    if (key.find(' ') != std::string::npos && key.size() > 24) return std::nullopt;
    return Header{key, i + 1};
  }

  static int firstNonSpace(const std::string& s) {
    int i = 0;
    while (i < static_cast<int>(s.size()) && isSpace(s[i])) ++i;
    return i;
  }

  /// Position of the production arrow `-->` (or `->`) at parenthesis depth 0, with its length.
  static std::pair<int, int> findArrow(const std::string& s) {
    for (const char* arrow : {"-->", "->"}) {
      int depth = 0;
      int n = static_cast<int>(std::string_view(arrow).size());
      for (int i = 0; i + n <= static_cast<int>(s.size()); ++i) {
        if (s[i] == '(') ++depth;
        else if (s[i] == ')') --depth;
        else if (depth == 0 && s.compare(i, n, arrow) == 0) return {i, n};
      }
    }
    return {-1, 0};
  }

  // ---- pass 1: module declarations and #defines -----------------------------------------

  void firstPass() {
    if (pendingComment_.first) error(pendingComment_.first, pendingComment_.second, "unterminated comment '/*'");
    std::map<std::string, int> defineLines;
    for (int line = 1; line <= static_cast<int>(clean_.size()); ++line) {
      const std::string& s = clean_[line - 1];
      int b = firstNonSpace(s);
      if (b >= static_cast<int>(s.size())) continue;
      if (s.compare(b, 10, "endlsystem") == 0) break;
      if (s.compare(b, 7, "#define") == 0 && (b + 7 == static_cast<int>(s.size()) || isSpace(s[b + 7]))) {
        int i = b + 7;
        while (i < static_cast<int>(s.size()) && isSpace(s[i])) ++i;
        int nb = i;
        while (i < static_cast<int>(s.size()) && isIdentChar(s[i])) ++i;
        if (nb == i || !isIdentStart(s[nb])) {
          error(line, nb, "expected a name after '#define'");
          continue;
        }
        std::string name = s.substr(nb, i - nb);
        if (defineLines.count(name)) {
          error(line, nb, "'" + name + "' is already defined at line " + std::to_string(defineLines[name]));
          continue;
        }
        defineLines[name] = line;
        Span value = trim(Span{line, i, static_cast<int>(s.size())});
        if (value.b == value.e) {
          error(line, i, "expected a value after '#define " + name + "'");
          continue;
        }
        double v = 0;
        std::optional<double> compiled = constantExpr(value, "#define " + name);
        auto ov = std::find_if(overrides_.defines.rbegin(), overrides_.defines.rend(), [&](const DefineOverride& o) { return o.name == name; });
        if (ov != overrides_.defines.rend()) v = ov->value;
        else if (compiled) v = *compiled;
        else continue;
        defines_[name] = v;
        prog_.defines.emplace_back(name, v);
      } else if (s[b] == '#') {
        int i = b + 1;
        while (i < static_cast<int>(s.size()) && isIdentChar(s[i])) ++i;
        std::string word = s.substr(b, i - b);
        error(line, b, "unknown directive '" + word + "'" + didYouMean(word, {"#define"}));
      } else if (s.compare(b, 6, "module") == 0 && (b + 6 == static_cast<int>(s.size()) || isSpace(s[b + 6])) &&
                 findArrow(s).first < 0) {
        declareModules(line, b + 6);
      }
    }
    for (const DefineOverride& o : overrides_.defines) {
      if (defines_.count(o.name)) continue;
      std::vector<std::string> names;
      for (auto& [n, v] : prog_.defines) names.push_back(n);
      SourceLoc loc = o.loc;
      if (loc.file.empty()) loc.file = prog_.fileName;
      diags_.error(loc, "no '#define " + o.name + "' in " + prog_.fileName + didYouMean(o.name, names));
    }
  }

  void declareModules(int line, int from) {
    const std::string& s = clean_[line - 1];
    int i = from;
    int n = static_cast<int>(s.size());
    bool any = false;
    while (i < n) {
      while (i < n && (isSpace(s[i]) || s[i] == ',')) ++i;
      if (i >= n) break;
      int nb = i;
      while (i < n && !isSpace(s[i]) && s[i] != ',' && s[i] != '(') ++i;
      std::string name = s.substr(nb, i - nb);
      bool valid = !name.empty() && isIdentStart(name[0]) &&
                   std::all_of(name.begin(), name.end(), [](char c) { return isIdentChar(c); });
      if (!valid) {
        error(line, nb, "invalid module name '" + name + "' (letters, digits and '_', starting with a letter)");
      } else {
        any = true;
        prog_.symbols.intern(name);
        if (name.size() > 1 && std::find(multiNames_.begin(), multiNames_.end(), name) == multiNames_.end()) multiNames_.push_back(name);
      }
      while (i < n && isSpace(s[i])) ++i;
      if (i < n && s[i] == '(') {  // lpfg-style `module Apex(float)`: the declaration's types are ignored
        while (i < n && s[i] != ')') ++i;
        if (i < n) ++i;
      }
    }
    if (!any && diags_.items().empty()) error(line, from, "expected module names after 'module'");
  }

  // ---- pass 2: headers and productions --------------------------------------------------

  void secondPass() {
    Block block = Block::Main;
    for (int line = 1; line <= static_cast<int>(clean_.size()); ++line) {
      const std::string& s = clean_[line - 1];
      int b = firstNonSpace(s);
      if (b >= static_cast<int>(s.size())) continue;
      if (s.compare(b, 10, "endlsystem") == 0) {
        Span rest = trim(Span{line, b + 10, static_cast<int>(s.size())});
        if (rest.b != rest.e) error(line, rest.b, "unexpected text after 'endlsystem'");
        break;
      }
      if (s[b] == '#') continue;
      if (s.compare(b, 6, "module") == 0 && (b + 6 == static_cast<int>(s.size()) || isSpace(s[b + 6])) && findArrow(s).first < 0) continue;
      auto header = headerOf(s, b);
      bool known = header && std::find(std::begin(kHeaders), std::end(kHeaders), header->key) != std::end(kHeaders);
      if (known) {
        handleHeader(line, b, *header, block);
        continue;
      }
      auto [arrow, arrowLen] = findArrow(s);
      if (arrow >= 0) {
        parseProduction(line, b, arrow, arrowLen, block);
        continue;
      }
      if (header) {
        std::vector<std::string> keys(std::begin(kHeaders), std::end(kHeaders));
        error(line, b, "unknown header '" + header->key + ":'" + didYouMean(header->key, keys));
      } else {
        error(line, b, "expected a production ('pred --> successor') or a header such as 'axiom:'");
      }
    }
  }

  void once(const std::string& key, int line, int col) {
    auto [it, inserted] = seen_.emplace(key, line);
    if (!inserted) error(line, col, "duplicate '" + key + ":' (first at line " + std::to_string(it->second) + ")");
  }

  void handleHeader(int line, int b, const Header& h, Block& block) {
    const std::string& s = clean_[line - 1];
    Span value = trim(Span{line, h.valueBegin, static_cast<int>(s.size())});
    std::string_view v = view(value);
    if (h.key == "lsystem") {
      once(h.key, line, b);
      prog_.name = std::string(v);
    } else if (h.key == "derivation length") {
      once(h.key, line, b);
      if (auto d = constantExpr(value, "derivation length")) {
        if (*d < 0 || *d != std::floor(*d) || *d > 1e6) {
          error(line, value.b, "derivation length must be a whole number from 0 to 1000000, got " + formatNumber(*d));
        } else {
          prog_.derivationLength = static_cast<int>(*d);
          prog_.lengthLoc = SourceLoc{prog_.fileName, line, b + 1};
          prog_.lengthLine = raw_[line - 1];
        }
      }
    } else if (h.key == "seed") {
      once(h.key, line, b);
      uint64_t seed = 0;
      auto r = std::from_chars(v.data(), v.data() + v.size(), seed);
      if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size())
        error(line, value.b, "seed must be a non-negative integer below 2^64, got '" + std::string(v) + "'");
      else
        prog_.seed = seed;
    } else if (h.key == "angle") {
      once(h.key, line, b);
      if (auto d = constantExpr(value, "angle")) {
        prog_.hasAngle = true;
        prog_.angleDeg = *d;
      }
    } else if (h.key == "axiom") {
      once(h.key, line, b);
      std::vector<RawModule> mods;
      if (value.b == value.e) error(line, value.b, "the axiom is empty");
      else if (tokenizeModules(line, value.b, value.e, mods) && checkBrackets(line, mods, "the axiom")) {
        noteWritten(line, mods);
        axiomModules_ = std::move(mods);
        axiomLine_ = line;
        prog_.axiomLoc = SourceLoc{prog_.fileName, line, b + 1};
        prog_.axiomLine = raw_[line - 1];
      }
    } else if (h.key == "ignore" || h.key == "consider") {
      once(h.key, line, b);
      if (block != Block::Main) error(line, b, "'" + h.key + ":' belongs before the decomposition and interpretation blocks");
      std::vector<RawModule> mods;
      if (tokenizeModules(line, value.b, value.e, mods)) {
        for (const RawModule& m : mods) {
          if (m.hasParens) error(line, m.col, "'" + h.key + ":' lists symbols without parameters");
          else if (m.name == "[" || m.name == "]") error(line, m.col, "brackets cannot be ignored or considered: context matching always follows them");
          else (h.key == "ignore" ? ignoreList_ : considerList_).push_back(prog_.symbols.intern(m.name));
        }
      }
      if (seen_.count("ignore") && seen_.count("consider") && h.key == (seen_["ignore"] < seen_["consider"] ? "consider" : "ignore"))
        error(line, b, "use either 'ignore:' or 'consider:', not both");
    } else if (h.key == "decomposition") {
      once(h.key, line, b);
      if (value.b != value.e) error(line, value.b, "unexpected text after 'decomposition:'");
      block = Block::Decomposition;
    } else if (h.key == "interpretation" || h.key == "homomorphism") {
      once("interpretation", line, b);
      if (value.b != value.e && v != "no warnings" && v != "warnings")
        error(line, value.b, "unexpected text after '" + h.key + ":'");
      block = Block::Interpretation;
    } else if (h.key == "maximum depth") {
      if (block == Block::Main) {
        error(line, b, "'maximum depth:' belongs in a 'decomposition:' or 'interpretation:' block");
        return;
      }
      once(block == Block::Decomposition ? "decomposition maximum depth" : "interpretation maximum depth", line, b);
      if (auto d = constantExpr(value, "maximum depth")) {
        if (*d < 1 || *d != std::floor(*d) || *d > 256)
          error(line, value.b, "maximum depth must be a whole number from 1 to 256, got " + formatNumber(*d));
        else
          (block == Block::Decomposition ? prog_.decomposition : prog_.interpretation).maxDepth = static_cast<int>(*d);
      }
    }
  }

  /// Index of the first c at parenthesis depth 0 in [b, e), or -1.
  int findTop(int line, int b, int e, char c) const {
    const std::string& s = clean_[line - 1];
    int depth = 0;
    for (int i = b; i < e; ++i) {
      if (s[i] == '(') ++depth;
      else if (s[i] == ')') --depth;
      else if (depth == 0 && s[i] == c) return i;
    }
    return -1;
  }

  int findTopLast(int line, int b, int e, char c) const {
    const std::string& s = clean_[line - 1];
    int depth = 0;
    int found = -1;
    for (int i = b; i < e; ++i) {
      if (s[i] == '(') ++depth;
      else if (s[i] == ')') --depth;
      else if (depth == 0 && s[i] == c) found = i;
    }
    return found;
  }

  bool isStar(Span sp) const { return view(trim(sp)) == "*"; }

  void parseProduction(int line, int b, int arrow, int arrowLen, Block block) {
    const std::string& s = clean_[line - 1];
    int n = static_cast<int>(s.size());
    Production p;
    size_t diagsBefore = diags_.items().size();
    // Split `lc < pred > rc : cond` and `succ : weight`.
    int colon = findTop(line, b, arrow, ':');
    int headEnd = colon >= 0 ? colon : arrow;
    Span lc{line, b, b}, pred{line, b, headEnd}, rc{line, headEnd, headEnd};
    int lt = findTop(line, b, headEnd, '<');
    if (lt >= 0) {
      lc = Span{line, b, lt};
      pred.b = lt + 1;
    }
    int gt = findTop(line, pred.b, headEnd, '>');
    if (gt >= 0) {
      rc = Span{line, gt + 1, headEnd};
      pred.e = gt;
    }
    Span cond{line, colon >= 0 ? colon + 1 : arrow, arrow};
    int succBegin = arrow + arrowLen;
    int wcolon = findTopLast(line, succBegin, n, ':');
    Span succ{line, succBegin, wcolon >= 0 ? wcolon : n};
    Span weight{line, wcolon >= 0 ? wcolon + 1 : n, n};

    std::vector<std::string> varNames;
    // Predecessor.
    pred = trim(pred);
    std::vector<RawModule> predMods;
    if (pred.b == pred.e) {
      error(line, pred.b, "missing predecessor before '" + s.substr(arrow, arrowLen) + "'");
      return;
    }
    if (!tokenizeModules(line, pred.b, pred.e, predMods)) return;
    if (predMods.size() != 1) {
      error(line, predMods.size() > 1 ? predMods[1].col : pred.b, "a predecessor must be a single module");
      return;
    }
    if (predMods[0].name == "[" || predMods[0].name == "]") {
      error(line, predMods[0].col, "a bracket cannot be a predecessor");
      return;
    }
    // Contexts (textual order: left, predecessor, right).
    lc = trim(lc);
    rc = trim(rc);
    if (lc.b != lc.e && !isStar(lc)) {
      if (block != Block::Main) error(line, lc.b, std::string("context is not allowed in ") + blockName(block) + " rules");
      else p.left = pattern(lc, varNames, true);
    }
    p.loc = SourceLoc{prog_.fileName, line, predMods[0].col + 1};
    p.text = std::string(view(pred));
    p.sourceLine = raw_[line - 1];
    p.predecessor = prog_.symbols.intern(predMods[0].name);
    p.predFirstVar = static_cast<uint16_t>(varNames.size());
    p.predParams = static_cast<uint16_t>(formals(predMods[0], varNames));
    arityUses_.push_back({predMods[0].name, p.predParams, line, predMods[0].col, moduleText(line, predMods[0]), false});
    if (rc.b != rc.e && !isStar(rc)) {
      if (block != Block::Main) error(line, rc.b, std::string("context is not allowed in ") + blockName(block) + " rules");
      else p.right = pattern(rc, varNames, false);
    }
    if (diags_.items().size() != diagsBefore) return;
    usesRandom_ = false;
    // Condition.
    cond = trim(cond);
    if (colon >= 0 && cond.b == cond.e) error(line, colon, "missing condition after ':' (write '*' for none)");
    else if (cond.b != cond.e && !isStar(cond)) {
      size_t before = prog_.code.size();
      if (compileExpr(cond, varNames, "condition")) {
        if (prog_.code.size() == before + 1 && prog_.code.back().op == Op::Const && prog_.code.back().c != 0) prog_.code.pop_back();
        else p.condition = CodeRange{static_cast<uint32_t>(before), static_cast<uint32_t>(prog_.code.size())};
      }
    }
    // Successor.
    succ = trim(succ);
    if (succ.b == succ.e) error(line, succ.b, "missing successor (write '*' for the empty string)");
    else if (!isStar(succ)) {
      std::vector<RawModule> mods;
      if (tokenizeModules(line, succ.b, succ.e, mods) && checkBrackets(line, mods, "the successor")) {
        noteWritten(line, mods);
        for (const RawModule& m : mods) {
          SuccModule sm;
          sm.symbol = prog_.symbols.intern(m.name);
          sm.firstArg = static_cast<uint32_t>(p.args.size());
          sm.argCount = static_cast<uint16_t>(m.args.size());
          for (const Span& a : m.args) p.args.push_back(compileArg(trim(a), varNames));
          p.successor.push_back(sm);
        }
      }
    }
    // Weight.
    if (wcolon >= 0) {
      weight = trim(weight);
      if (weight.b == weight.e) error(line, wcolon, "missing weight after ':'");
      else if (auto w = constantExpr(weight, "weight")) {
        if (*w < 0) error(line, weight.b, "a weight must not be negative, got " + formatNumber(*w));
        p.stochastic = true;
        p.weight = *w;
      }
    }
    p.usesRandom = usesRandom_;
    RuleSet& rs = block == Block::Main ? prog_.productions : block == Block::Decomposition ? prog_.decomposition : prog_.interpretation;
    rs.productions.push_back(std::move(p));
  }

  /// The module m as written (name and parameter list).
  std::string moduleText(int line, const RawModule& m) const {
    if (!m.hasParens) return m.name;
    const std::string& s = clean_[line - 1];
    int end = m.args.empty() ? static_cast<int>(s.find(')', m.col)) : m.args.back().e;
    return s.substr(m.col, end + 1 - m.col);
  }

  /// Reports brackets that do not pair up in mods (an axiom or a successor, named by where).
  bool checkBrackets(int line, const std::vector<RawModule>& mods, const char* where) {
    std::vector<int> open;
    bool ok = true;
    for (const RawModule& m : mods) {
      if (m.name == "[") {
        open.push_back(m.col);
      } else if (m.name == "]") {
        if (open.empty()) {
          error(line, m.col, std::string("unmatched ']' in ") + where);
          ok = false;
        } else {
          open.pop_back();
        }
      }
    }
    for (int col : open) {
      error(line, col, std::string("unclosed '[' in ") + where + " (no matching ']')");
      ok = false;
    }
    return ok;
  }

  /// Records the parameter count of every module written in an axiom or successor.
  void noteWritten(int line, const std::vector<RawModule>& mods) {
    for (const RawModule& m : mods) written_[m.name].emplace(static_cast<int>(m.args.size()), std::pair{line, m.col});
  }

  /// A predecessor or context module whose parameter count no written module of its symbol
  /// has can never match (cpfg and lpfg match a module only with the same number of
  /// parameters): report it. Symbols never written at all are left alone.
  void checkArities() {
    for (const ArityUse& u : arityUses_) {
      auto it = written_.find(u.name);
      if (it == written_.end() || it->second.count(u.arity)) continue;
      const auto& counts = it->second;
      std::string list;
      size_t k = 0;
      for (const auto& entry : counts) {
        if (k > 0) list += k + 1 == counts.size() ? " or " : ", ";
        list += std::to_string(entry.first);
        ++k;
      }
      bool one = counts.size() == 1 && counts.begin()->first == 1;
      const auto& first = counts.begin()->second;
      error(u.line, u.col,
            std::string(u.context ? "context '" : "predecessor '") + u.text + "' has " + std::to_string(u.arity) +
                " parameter" + (u.arity == 1 ? "" : "s") + ", but '" + u.name + "' is only written with " + list +
                (one ? " parameter" : " parameters") + " (as at line " + std::to_string(first.first) + ":" +
                std::to_string(first.second + 1) + "), so this production never applies");
    }
  }

  static const char* blockName(Block b) {
    return b == Block::Decomposition ? "decomposition" : b == Block::Interpretation ? "interpretation" : "main";
  }

  /// Registers m's formal parameter names; returns their count.
  int formals(const RawModule& m, std::vector<std::string>& varNames) {
    for (const Span& a0 : m.args) {
      Span a = trim(a0);
      std::string name(view(a));
      bool valid = !name.empty() && isIdentStart(name[0]) && std::all_of(name.begin(), name.end(), [](char c) { return isIdentChar(c); });
      if (!valid) {
        error(a.line, a.b, "expected a parameter name, got '" + name + "'");
      } else if (std::find(varNames.begin(), varNames.end(), name) != varNames.end()) {
        error(a.line, a.b, "parameter '" + name + "' is already used in this production");
      } else if (defines_.count(name)) {
        error(a.line, a.b, "parameter '" + name + "' has the name of a #define");
      } else if (varNames.size() >= static_cast<size_t>(detail::kMaxVars)) {
        error(a.line, a.b, "too many parameters in one production (at most " + std::to_string(detail::kMaxVars) + ")");
      }
      varNames.push_back(name);
    }
    return static_cast<int>(m.args.size());
  }

  std::vector<PatternItem> pattern(Span sp, std::vector<std::string>& varNames, bool left) {
    std::vector<RawModule> mods;
    std::vector<PatternItem> items;
    if (!tokenizeModules(sp.line, sp.b, sp.e, mods)) return items;
    for (const RawModule& m : mods) {
      PatternItem it;
      if (m.name == "[" || m.name == "]") {
        if (left) {
          error(sp.line, m.col, "brackets are not allowed in a left context");
          continue;
        }
        it.openBracket = m.name == "[";
        it.closeBracket = m.name == "]";
      } else {
        it.symbol = prog_.symbols.intern(m.name);
        it.firstVar = static_cast<uint16_t>(varNames.size());
        it.paramCount = static_cast<uint16_t>(formals(m, varNames));
        arityUses_.push_back({m.name, it.paramCount, sp.line, m.col, moduleText(sp.line, m), true});
      }
      items.push_back(it);
    }
    return items;
  }

  // ---- expressions -------------------------------------------------------------------

  struct Node {
    Op op = Op::Const;
    double value = 0;
    uint16_t var = 0;
    int kids[2] = {-1, -1};
  };

  struct Tok {
    enum Kind { Num, Ident, Punct, End } kind = End;
    std::string_view text;
    double value = 0;
    int col = 0;  ///< 0-based
  };

  struct ExprState {
    Span span;
    const std::vector<std::string>* vars = nullptr;
    std::vector<Node> nodes;
    Tok tok;
    int pos = 0;
    int depth = 0;  ///< nesting of unary operators and parentheses
  };
  static constexpr int kMaxNesting = 48;

  void lex(ExprState& st) {
    const std::string& s = clean_[st.span.line - 1];
    int i = st.pos;
    while (i < st.span.e && isSpace(s[i])) ++i;
    Tok t;
    t.col = i;
    if (i >= st.span.e) {
      t.kind = Tok::End;
      st.pos = i;
      st.tok = t;
      return;
    }
    char c = s[i];
    if (std::isdigit(static_cast<unsigned char>(c)) || (c == '.' && i + 1 < st.span.e && std::isdigit(static_cast<unsigned char>(s[i + 1])))) {
      int j = i;
      while (j < st.span.e && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.')) ++j;
      if (j < st.span.e && (s[j] == 'e' || s[j] == 'E')) {
        int k = j + 1;
        if (k < st.span.e && (s[k] == '+' || s[k] == '-')) ++k;
        if (k < st.span.e && std::isdigit(static_cast<unsigned char>(s[k]))) {
          j = k;
          while (j < st.span.e && std::isdigit(static_cast<unsigned char>(s[j]))) ++j;
        }
      }
      double v = 0;
      auto r = std::from_chars(s.data() + i, s.data() + j, v);
      if (r.ec != std::errc() || r.ptr != s.data() + j) {
        error(st.span.line, i, "malformed number '" + s.substr(i, j - i) + "'");
        throw ExprFail{};
      }
      t.kind = Tok::Num;
      t.value = v;
      t.text = std::string_view(s).substr(i, j - i);
      st.pos = j;
    } else if (isIdentStart(c)) {
      int j = i;
      while (j < st.span.e && isIdentChar(s[j])) ++j;
      t.kind = Tok::Ident;
      t.text = std::string_view(s).substr(i, j - i);
      st.pos = j;
    } else {
      static const char* two[] = {"<=", ">=", "==", "!=", "&&", "||"};
      int len = 0;
      for (const char* op : two)
        if (i + 1 < st.span.e && s.compare(i, 2, op) == 0) len = 2;
      if (!len) {
        if (std::string_view("+-*/^<>!(),").find(c) == std::string_view::npos) {
          error(st.span.line, i, std::string("unexpected character '") + c + "' in expression");
          throw ExprFail{};
        }
        len = 1;
      }
      t.kind = Tok::Punct;
      t.text = std::string_view(s).substr(i, len);
      st.pos = i + len;
    }
    st.tok = t;
  }

  bool isPunct(const ExprState& st, std::string_view p) const { return st.tok.kind == Tok::Punct && st.tok.text == p; }

  int node(ExprState& st, Op op, int a = -1, int b = -1) {
    Node n;
    n.op = op;
    n.kids[0] = a;
    n.kids[1] = b;
    st.nodes.push_back(n);
    return static_cast<int>(st.nodes.size()) - 1;
  }

  [[noreturn]] void unexpected(ExprState& st, const char* what) {
    if (st.tok.kind == Tok::End) error(st.span.line, st.tok.col, std::string("expected ") + what + " at the end of the expression");
    else error(st.span.line, st.tok.col, std::string("expected ") + what + ", got '" + std::string(st.tok.text) + "'");
    throw ExprFail{};
  }

  int parseBinary(ExprState& st, int level) {
    static const std::vector<std::vector<std::pair<const char*, Op>>> levels = {
        {{"||", Op::Or}},
        {{"&&", Op::And}},
        {{"==", Op::Eq}, {"!=", Op::Ne}},
        {{"<", Op::Lt}, {"<=", Op::Le}, {">", Op::Gt}, {">=", Op::Ge}},
        {{"+", Op::Add}, {"-", Op::Sub}},
        {{"*", Op::Mul}, {"/", Op::Div}},
    };
    if (level == static_cast<int>(levels.size())) return parseUnary(st);
    int lhs = parseBinary(st, level + 1);
    for (;;) {
      const std::pair<const char*, Op>* hit = nullptr;
      for (const auto& op : levels[level])
        if (isPunct(st, op.first)) hit = &op;
      if (!hit) return lhs;
      lex(st);
      int rhs = parseBinary(st, level + 1);
      lhs = node(st, hit->second, lhs, rhs);
    }
  }

  int parseUnary(ExprState& st) {
    if (++st.depth > kMaxNesting) {
      error(st.span.line, st.tok.col, "expression is nested too deeply (more than " + std::to_string(kMaxNesting) + " levels)");
      throw ExprFail{};
    }
    struct Leave {
      int& d;
      ~Leave() { --d; }
    } leave{st.depth};
    if (isPunct(st, "-")) {
      lex(st);
      return node(st, Op::Neg, parseUnary(st));
    }
    if (isPunct(st, "+")) {
      lex(st);
      return parseUnary(st);
    }
    if (isPunct(st, "!")) {
      lex(st);
      return node(st, Op::Not, parseUnary(st));
    }
    int base = parsePrimary(st);
    if (isPunct(st, "^")) {
      lex(st);
      return node(st, Op::Pow, base, parseUnary(st));
    }
    return base;
  }

  int parsePrimary(ExprState& st) {
    if (st.tok.kind == Tok::Num) {
      int n = node(st, Op::Const);
      st.nodes[n].value = st.tok.value;
      lex(st);
      return n;
    }
    if (isPunct(st, "(")) {
      lex(st);
      int inner = parseBinary(st, 0);
      if (!isPunct(st, ")")) unexpected(st, "')'");
      lex(st);
      return inner;
    }
    if (st.tok.kind == Tok::Ident) {
      Tok id = st.tok;
      std::string name(id.text);
      lex(st);
      if (isPunct(st, "(")) {
        const FunctionInfo* fn = nullptr;
        for (const FunctionInfo& f : kFunctions)
          if (name == f.name) fn = &f;
        if (!fn) {
          std::vector<std::string> names;
          for (const FunctionInfo& f : kFunctions) names.emplace_back(f.name);
          error(st.span.line, id.col, "unknown function '" + name + "'" + didYouMean(name, names));
          throw ExprFail{};
        }
        lex(st);
        std::vector<int> args;
        if (!isPunct(st, ")")) {
          for (;;) {
            args.push_back(parseBinary(st, 0));
            if (isPunct(st, ",")) {
              lex(st);
              continue;
            }
            break;
          }
        }
        if (!isPunct(st, ")")) unexpected(st, "')' or ','");
        lex(st);
        if (static_cast<int>(args.size()) != fn->arity) {
          error(st.span.line, id.col, "function '" + name + "' takes " + std::to_string(fn->arity) + " argument" +
                                           (fn->arity == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
          throw ExprFail{};
        }
        if (fn->op == Op::Ran || fn->op == Op::Nran) usesRandom_ = true;
        return node(st, fn->op, args[0], args.size() > 1 ? args[1] : -1);
      }
      if (st.vars) {
        auto it = std::find(st.vars->begin(), st.vars->end(), name);
        if (it != st.vars->end()) {
          int n = node(st, Op::Var);
          st.nodes[n].var = static_cast<uint16_t>(it - st.vars->begin());
          return n;
        }
      }
      auto d = defines_.find(name);
      if (d != defines_.end()) {
        int n = node(st, Op::Const);
        st.nodes[n].value = d->second;
        return n;
      }
      std::vector<std::string> names;
      if (st.vars) names = *st.vars;
      for (auto& [k, v] : defines_) names.push_back(k);
      error(st.span.line, id.col, "unknown name '" + name + "'" + didYouMean(name, names));
      throw ExprFail{};
    }
    unexpected(st, "a number, a name or '('");
  }

  /// Emits node n into prog_.code with constant folding; returns true when it folded to one Const.
  bool emit(const ExprState& st, int n, int& depth, int& maxDepth) {
    const Node& nd = st.nodes[n];
    int arity = arityOf(nd.op);
    if (arity == 0) {
      Instr in;
      in.op = nd.op;
      in.c = nd.value;
      in.var = nd.var;
      prog_.code.push_back(in);
      maxDepth = std::max(maxDepth, ++depth);
      return nd.op == Op::Const;
    }
    bool allConst = true;
    for (int k = 0; k < arity; ++k) allConst &= emit(st, nd.kids[k], depth, maxDepth);
    Instr in;
    in.op = nd.op;
    prog_.code.push_back(in);
    depth -= arity - 1;
    if (allConst && nd.op != Op::Ran && nd.op != Op::Nran) {
      size_t first = prog_.code.size() - 1 - arity;
      double v = detail::evalCode(prog_.code.data() + first, prog_.code.data() + prog_.code.size(), nullptr, nullptr);
      prog_.code.resize(first);
      Instr c;
      c.c = v;
      prog_.code.push_back(c);
      return true;
    }
    return false;
  }

  /// Compiles the expression in sp onto prog_.code. Returns false (error reported) on failure.
  bool compileExpr(Span sp, const std::vector<std::string>& vars, const char* what) {
    ExprState st;
    st.span = sp;
    st.vars = &vars;
    st.pos = sp.b;
    size_t before = prog_.code.size();
    try {
      lex(st);
      int root = parseBinary(st, 0);
      if (st.tok.kind != Tok::End) unexpected(st, "an operator");
      int depth = 0, maxDepth = 0;
      emit(st, root, depth, maxDepth);
      if (maxDepth > detail::kMaxStack) {
        error(sp.line, sp.b, std::string(what) + " is nested too deeply");
        prog_.code.resize(before);
        return false;
      }
      if (prog_.code.size() == before + 1 && prog_.code.back().op == Op::Const && !std::isfinite(prog_.code.back().c)) {
        error(sp.line, sp.b, std::string(what) + " is not finite (" + formatNumber(prog_.code.back().c) + ")");
        prog_.code.resize(before);
        return false;
      }
      return true;
    } catch (const ExprFail&) {
      prog_.code.resize(before);
      return false;
    }
  }

  /// A constant expression (defines allowed, no parameters, no random draws).
  std::optional<double> constantExpr(Span sp, const std::string& what) {
    sp = trim(sp);
    if (sp.b == sp.e) {
      error(sp.line, sp.b, "missing value for " + what);
      return std::nullopt;
    }
    static const std::vector<std::string> none;
    size_t before = prog_.code.size();
    bool rnd = usesRandom_;
    usesRandom_ = false;
    bool ok = compileExpr(sp, none, what.c_str());
    bool drew = usesRandom_;
    usesRandom_ = rnd;
    if (!ok) return std::nullopt;
    std::optional<double> v;
    if (drew || prog_.code.size() != before + 1) error(sp.line, sp.b, what + " must be a constant");
    else v = prog_.code.back().c;
    prog_.code.resize(before);
    return v;
  }

  Arg compileArg(Span sp, const std::vector<std::string>& vars) {
    Arg a;
    size_t before = prog_.code.size();
    if (!compileExpr(sp, vars, "parameter")) return a;
    const Instr* c = prog_.code.data() + before;
    size_t len = prog_.code.size() - before;
    if (len == 1 && c[0].op == Op::Const) a = Arg{ArgKind::Const, 0, c[0].c, {}};
    else if (len == 1 && c[0].op == Op::Var) a = Arg{ArgKind::Var, c[0].var, 0, {}};
    else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Add) a = Arg{ArgKind::VarAddConst, c[0].var, c[1].c, {}};
    else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Sub) a = Arg{ArgKind::VarAddConst, c[0].var, -c[1].c, {}};
    else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Mul) a = Arg{ArgKind::VarMulConst, c[0].var, c[1].c, {}};
    else if (len == 3 && c[0].op == Op::Const && c[1].op == Op::Var && c[2].op == Op::Mul) a = Arg{ArgKind::VarMulConst, c[1].var, c[0].c, {}};
    else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Div) a = Arg{ArgKind::VarDivConst, c[0].var, c[1].c, {}};
    else {
      a.kind = ArgKind::Expr;
      a.code = CodeRange{static_cast<uint32_t>(before), static_cast<uint32_t>(prog_.code.size())};
      return a;
    }
    prog_.code.resize(before);
    return a;
  }

  /// Appends modules whose parameters are constant expressions (random draws use rng).
  void appendConstant(const std::vector<RawModule>& mods, int line, ModuleString& out, Rng* rng) {
    static const std::vector<std::string> none;
    for (const RawModule& m : mods) {
      SymbolId id = prog_.symbols.intern(m.name);
      std::vector<double> params;
      bool ok = true;
      for (const Span& a0 : m.args) {
        Span a = trim(a0);
        size_t before = prog_.code.size();
        bool rnd = usesRandom_;
        usesRandom_ = false;
        if (!compileExpr(a, none, "parameter")) {
          ok = false;
          usesRandom_ = rnd;
          continue;
        }
        if (usesRandom_ && !rng) {
          error(line, a.b, "random functions are not allowed here");
          ok = false;
        } else {
          double v = detail::evalCode(prog_.code.data() + before, prog_.code.data() + prog_.code.size(), nullptr, rng);
          if (!std::isfinite(v)) {
            error(line, a.b, "parameter is not finite (" + formatNumber(v) + ")");
            ok = false;
          }
          params.push_back(v);
        }
        usesRandom_ = rnd;
        prog_.code.resize(before);
      }
      if (ok) out.push(id, params);
    }
  }

  // ---- end of file -------------------------------------------------------------------

  void finish() {
    if (overrides_.derivationLength) {
      prog_.lengthLoc = SourceLoc{};  // the length no longer comes from the file
      prog_.lengthLine.clear();
      if (*overrides_.derivationLength < 0) diags_.error(SourceLoc{prog_.fileName, 0, 0}, "derivation length override must not be negative");
      prog_.derivationLength = *overrides_.derivationLength;
    }
    if (overrides_.seed) prog_.seed = *overrides_.seed;
    if (prog_.name.empty()) prog_.name = std::filesystem::path(prog_.fileName).stem().string();
    if (axiomLine_ == 0 && !seen_.count("axiom")) {
      diags_.error(SourceLoc{prog_.fileName, 0, 0}, "missing 'axiom:'");
    } else if (axiomLine_) {
      Rng rng(deriveSeed(prog_.seed, {kAxiomStream}));
      appendConstant(axiomModules_, axiomLine_, prog_.axiom, &rng);
    }
    // Ignore / consider table over every symbol, including ones interned late.
    prog_.ignored.assign(prog_.symbols.size(), 0);
    if (!considerList_.empty()) {
      std::fill(prog_.ignored.begin(), prog_.ignored.end(), 1);
      for (SymbolId id : considerList_) prog_.ignored[id] = 0;
    }
    for (SymbolId id : ignoreList_) prog_.ignored[id] = 1;
    prog_.ignored[prog_.openBracket] = prog_.ignored[prog_.closeBracket] = 0;
    for (SymbolId id : prog_.axiom.symbols) prog_.usesCut |= id == prog_.cut;
    for (const RuleSet* rs : {&prog_.productions, &prog_.decomposition})
      for (const Production& p : rs->productions)
        for (const SuccModule& m : p.successor) prog_.usesCut |= m.symbol == prog_.cut;
    for (RuleSet* rs : {&prog_.productions, &prog_.decomposition, &prog_.interpretation}) {
      rs->bySymbol.assign(prog_.symbols.size(), {});
      for (uint32_t i = 0; i < rs->productions.size(); ++i) {
        rs->bySymbol[rs->productions[i].predecessor].push_back(i);
        rs->anyContext |= rs->productions[i].hasContext();
      }
      rs->finalize();
    }
  }

  std::string_view text_;
  GrammarOverrides overrides_;
  Program prog_;
  DiagnosticList diags_;
  std::vector<std::string> raw_, clean_;
  std::vector<std::string> multiNames_;
  std::unordered_map<std::string, double> defines_;
  std::map<std::string, int> seen_;
  std::vector<RawModule> axiomModules_;
  int axiomLine_ = 0;
  std::vector<SymbolId> ignoreList_, considerList_;
  std::pair<int, int> pendingComment_{0, 0};
  /// A predecessor or context module with its parameter count, checked by checkArities().
  struct ArityUse {
    std::string name;
    int arity;
    int line, col;  ///< col 0-based
    std::string text;
    bool context;
  };
  std::vector<ArityUse> arityUses_;
  /// Per symbol: the parameter counts it is written with, each with its first (line, col).
  std::map<std::string, std::map<int, std::pair<int, int>>> written_;
  bool usesRandom_ = false;
};

}  // namespace

Grammar::Grammar() : program_(std::make_shared<Program>()) {}

const std::string& Grammar::name() const { return program_->name; }
const std::string& Grammar::fileName() const { return program_->fileName; }
int Grammar::derivationLength() const { return program_->derivationLength; }
uint64_t Grammar::seed() const { return program_->seed; }
std::optional<double> Grammar::angleDeg() const {
  return program_->hasAngle ? std::optional<double>(program_->angleDeg) : std::nullopt;
}
const SymbolTable& Grammar::symbols() const { return program_->symbols; }
const ModuleString& Grammar::axiom() const { return program_->axiom; }
std::optional<double> Grammar::define(std::string_view name) const {
  for (auto& [n, v] : program_->defines)
    if (n == name) return v;
  return std::nullopt;
}
std::vector<std::string> Grammar::defineNames() const {
  std::vector<std::string> names;
  for (auto& [n, v] : program_->defines) names.push_back(n);
  return names;
}
size_t Grammar::productionCount() const { return program_->productions.productions.size(); }
bool Grammar::hasInterpretation() const { return !program_->interpretation.empty(); }

Grammar parseGrammar(std::string_view text, const std::string& fileName, const GrammarOverrides& overrides) {
  Parser parser(text, fileName, overrides);
  Grammar g;
  g.program_ = parser.run();
  return g;
}

Grammar loadGrammar(const std::string& path, const GrammarOverrides& overrides) {
  std::string text;
  try {
    text = readFile(path);
  } catch (const std::exception&) {
    throw InputError(SourceLoc{path, 0, 0}, "cannot read the grammar file");
  }
  return parseGrammar(text, path, overrides);
}

ModuleString parseModuleString(std::string_view text, SymbolTable& symbols, const std::string& fileName) {
  Parser parser("", fileName, {});
  parser.loadSingle(text, symbols);
  return parser.constantString(symbols);
}

}  // namespace sprig::lsystem
