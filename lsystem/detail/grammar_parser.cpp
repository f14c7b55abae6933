#include "lsystem/detail/grammar_parser.h"

#include <algorithm>
#include <tuple>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include "core/rng.h"
#include "core/text.h"
#include "lsystem/detail/expression_parser.h"
#include "lsystem/detail/scanner.h"

namespace sprig::lsystem::detail {

namespace {

/// Most `[` nested in one axiom or successor as written (docs/ROBUSTNESS.md).
constexpr size_t kMaxBracketDepth = 1024;

/// Stream id for random draws in axiom parameters.
constexpr uint64_t kAxiomStream = 0xfffffffffffffff1ull;

const char* const kHeaders[] = {"lsystem", "derivation length", "seed", "angle", "axiom", "ignore", "consider",
                                "decomposition", "interpretation", "homomorphism", "maximum depth", "endlsystem"};

enum class Block { Main, Decomposition, Interpretation };

/// True when line s has cpfg's `endlsystem` (any capitalization, as cpfg's `Endlsystem`) at b.
bool isEndLsystem(const std::string& s, int b) {
  if (static_cast<int>(s.size()) < b + 10) return false;
  for (int k = 0; k < 10; ++k)
    if (std::tolower(static_cast<unsigned char>(s[b + k])) != "endlsystem"[k]) return false;
  return true;
}

/// cpfg's block keywords written without a colon, alone on their line (`homomorphism`,
/// `Decomposition`, `homomorphism no warnings`): the header they stand for, or nullopt.
std::optional<Header> bareBlockKeyword(const std::string& s, int b) {
  std::string words;
  for (int i = b; i < static_cast<int>(s.size()); ++i) {
    char c = static_cast<char>(std::tolower(static_cast<unsigned char>(s[i])));
    if (isSpace(c)) {
      if (!words.empty() && words.back() != ' ') words += ' ';
    } else {
      words += c;
    }
  }
  while (!words.empty() && words.back() == ' ') words.pop_back();
  for (const char* key : {"homomorphism", "decomposition"}) {
    std::string k(key);
    if (words == k || words == k + " no warnings" || words == k + " warnings")
      return Header{k, b + static_cast<int>(k.size())};
  }
  return std::nullopt;
}


/// cpfg's `@L("format", values)` outside an interpretation rule (it would be in the string).
/// cpfg's interpretation-rule predecessor `@G` (expandGenCylRules).
constexpr const char* kGenCylPrefix = "@G";
constexpr const char* kLabelOutsideInterpretation =
    "cpfg's '@L' (label) is supported only in interpretation rules (Sprig draws no text: drawing one is an error)";

/// Most elements of all of cpfg's `define: { array ... }` arrays together.
constexpr uint32_t kMaxArrayElements = 1u << 24;

/// What Sprig reads of a sub-L-system (the end of the error for anything else in one).
constexpr const char* kSubReads =
    "Sprig reads a sub-L-system's productions, decomposition and interpretation rules and 'ignore:' or 'consider:'";

/// cpfg's blocks of statements over global variables, by header key.
const char* const kBlockHeaders[] = {"start", "end", "starteach", "start each", "endeach", "end each"};

/// True when line s, whose first non-space character is at b, declares modules
/// (`module Apex, Leaf`) rather than being a production of a module named `module`.
bool isModuleDeclaration(const std::string& s, int b) {
  return s.compare(b, 6, "module") == 0 && (b + 6 == static_cast<int>(s.size()) || isSpace(s[b + 6])) &&
         Scanner::findArrow(s).first < 0;
}

/*
 * GrammarParser: two passes over the scanned lines of one file, then a check and the
 * finishing touches, writing one Program.
 *
 *   pass 1   `#define` constants (with overrides) and `module` declarations, so that
 *            every expression and every module string of pass 2 may use them wherever
 *            they stand in the file;
 *   pass 2   headers (`axiom:`, `ignore:`, `decomposition:`, ...) and productions,
 *            each production compiled into its block's RuleSet;
 *   check    predecessors and contexts whose parameter count no written module has
 *            (only on an otherwise clean file);
 *   finish   overrides, the axiom's constant parameters, the ignore table, the lookup
 *            tables by symbol.
 *
 * Lines, spans and diagnostics belong to the Scanner; expressions to the
 * ExpressionParser, which appends onto Program::code. Errors are collected and thrown
 * once, at the end.
 */
class GrammarParser {
 public:
  GrammarParser(const std::string& fileName, const GrammarOverrides& overrides)
      : overrides_(overrides), scanner_(fileName) {
    prog_.fileName = fileName;
    prog_.dialect = dialectOf(fileName);
    prog_.floatParams = prog_.dialect == Dialect::Cpfg;
    scanner_.setDialect(prog_.dialect);
    for (size_t k = 0; k < kCpfgMultiNameCount; ++k) scanner_.addMultiName(kCpfgMultiNames[k]);
    expr_.setGlobals(&prog_.globals);
    prog_.cpfg.functions = overrides.cpfgFunctions;
    prog_.cpfg.curves = overrides.cpfgCurves;
    scanner_.setCpfgSurfaceIds(overrides.cpfgSurfaceIds, overrides.cpfgUndrawnSurfaceIds);
    if (prog_.dialect == Dialect::Cpfg) scanner_.setPredefined(overrides.cpfgFunctionNames);
    expr_.setTables(&prog_.cpfg);
    for (const char* s : kTurtleSymbols) prog_.symbols.intern(s);
    prog_.openBracket = static_cast<SymbolId>(prog_.symbols.find("["));
    prog_.closeBracket = static_cast<SymbolId>(prog_.symbols.find("]"));
    prog_.cut = static_cast<SymbolId>(prog_.symbols.find("%"));
    for (const char* s : kTurtleSymbols)
      if (std::string_view(s).size() > 1) scanner_.addMultiName(s);
  }

  /// Parses and compiles a grammar file's text.
  std::shared_ptr<Program> run(std::string_view text) {
    requireText(text, prog_.fileName, "a grammar file");
    scanner_.load(text);
    firstPass();
    secondPass();
    // Only on an otherwise clean file: a successor that failed to parse wrote nothing, and
    // its modules' parameter counts would be missed.
    if (!diags().hasErrors()) {
      checkArities();
      checkWrittenArities();
      for (const RuleSet* rs : {&prog_.productions, &prog_.decomposition, &prog_.interpretation}) checkWeights(*rs);
      for (const SubLsystem& sub : prog_.subLsystems)
        for (const RuleSet* rs : {&sub.productions, &sub.decomposition, &sub.interpretation}) checkWeights(*rs);
      checkSubLsystemCalls();
    }
    finish();
    diags().throwIfErrors();
    for (const Diagnostic& d : diags().items()) prog_.warnings.push_back(d);
    return std::make_shared<Program>(std::move(prog_));
  }

  /// Tokenizes every line of text as a constant module string over symbols (for
  /// parseModuleString); new symbols are interned into symbols.
  ModuleString constantString(std::string_view text, SymbolTable& symbols) {
    requireText(text, prog_.fileName, "a module string");
    scanner_.load(text);
    prog_.symbols = symbols;
    scanner_.clearMultiNames();
    for (size_t i = 0; i < symbols.size(); ++i)
      if (symbols.name(static_cast<SymbolId>(i)).size() > 1 && symbols.name(static_cast<SymbolId>(i))[0] != '~')
        scanner_.addMultiName(symbols.name(static_cast<SymbolId>(i)));
    for (size_t k = 0; k < kCpfgMultiNameCount; ++k) scanner_.addMultiName(kCpfgMultiNames[k]);
    ModuleString out;
    for (int line = 1; line <= scanner_.lineCount(); ++line) {
      std::vector<RawModule> mods;
      if (!scanner_.tokenizeModules(line, 0, static_cast<int>(scanner_.line(line).size()), mods)) continue;
      appendConstant(mods, out, nullptr);
    }
    diags().throwIfErrors();
    symbols = prog_.symbols;
    return out;
  }

 private:
  DiagnosticList& diags() { return scanner_.diagnostics(); }
  void error(int line, int col0, std::string msg) { scanner_.error(line, col0, std::move(msg)); }

  // ---- pass 1: module declarations and #defines -----------------------------------------

  /// Pass 1 (see the class comment), then overrides naming no `#define`.
  void firstPass() {
    if (auto [line, col] = scanner_.unterminatedComment(); line) error(line, col, "unterminated comment '/*'");
    std::map<std::string, int> defineLines;
    int gapUntil = 0;
    for (int line = 1; line <= scanner_.lineCount(); ++line) {
      const std::string& s = scanner_.line(line);
      int b = Scanner::firstNonSpace(s);
      if (b >= static_cast<int>(s.size())) continue;
      if (isEndLsystem(s, b)) {
        // cpfg: a later `lsystem:` starts a sub-L-system; only `#` lines count in between.
        gapUntil = prog_.dialect == Dialect::Cpfg ? nextLsystemHeader(line) : 0;
        if (!gapUntil) break;
        continue;
      }
      if (line < gapUntil && s[b] != '#') continue;
      if (s.compare(b, 7, "#define") == 0 && (b + 7 == static_cast<int>(s.size()) || isSpace(s[b + 7]))) {
        defineConstant(line, b, defineLines);
      } else if (s[b] == '#') {
        int i = b + 1;
        while (i < static_cast<int>(s.size()) && isSpace(s[i])) ++i;
        while (i < static_cast<int>(s.size()) && isIdentChar(s[i])) ++i;
        std::string word = s.substr(b, i - b);
        word.erase(std::remove_if(word.begin(), word.end(), [](char c) { return isSpace(c); }), word.end());
        static const char* const kCpp[] = {"#if", "#elif", "#line", "#pragma", "#error", "#warning"};
        if (std::find(std::begin(kCpp), std::end(kCpp), word) != std::end(kCpp))
          error(line, b, "cpfg's C preprocessor directive '" + word + "' is not supported (Sprig's preprocessor reads "
                         "#define, #undef, #include, #ifdef, #ifndef, #else and #endif)");
        else
          error(line, b, "unknown directive '" + word + "'" +
                             didYouMean(word, {"#define", "#undef", "#include", "#ifdef", "#ifndef", "#else", "#endif"}));
      } else if (isModuleDeclaration(s, b)) {
        declareModules(line, b + 6);
      }
    }
    for (const DefineOverride& o : overrides_.defines) {
      if (defines_.count(o.name)) continue;
      std::vector<std::string> names;
      for (auto& [n, v] : prog_.defines) names.push_back(n);
      SourceLoc loc = o.loc;
      if (loc.file.empty()) loc.file = prog_.fileName;
      diags().error(loc, "no '#define " + o.name + "' in " + prog_.fileName + didYouMean(o.name, names));
    }
  }

  /// `#define NAME expr` at column b of line: NAME's value (an override wins). defineLines
  /// maps each name defined so far to its line.
  void defineConstant(int line, int b, std::map<std::string, int>& defineLines) {
    const std::string& s = scanner_.line(line);
    int i = b + 7;
    while (i < static_cast<int>(s.size()) && isSpace(s[i])) ++i;
    int nb = i;
    while (i < static_cast<int>(s.size()) && isIdentChar(s[i])) ++i;
    if (nb == i || !isIdentStart(s[nb])) {
      error(line, nb, "expected a name after '#define'");
      return;
    }
    std::string name = s.substr(nb, i - nb);
    if (i < static_cast<int>(s.size()) && s[i] == '(') {
      error(line, nb, "cpfg's function-like macro '#define " + name + "(...)' (C preprocessor) is not supported");
      return;
    }
    if (defineLines.count(name)) {
      error(line, nb, "'" + name + "' is already defined at " + scanner_.lineRef(defineLines[name]));
      return;
    }
    defineLines[name] = line;
    Span value = scanner_.trim(Span{line, i, static_cast<int>(s.size())});
    if (value.b == value.e) {
      error(line, i, "expected a value after '#define " + name + "'");
      return;
    }
    // cpp's textual macros: a module string (`#define LEAF [+F]~l`) is not an expression.
    const std::string_view text = scanner_.view(value);
    if (text.find_first_of("[]$@{}~") != std::string_view::npos || (text.find('?') != std::string_view::npos && text.find(':') == std::string_view::npos)) {
      error(line, value.b, "cpfg's #define of a module string ('" + std::string(text) +
                               "', a C preprocessor macro) is not supported: only constants are");
      return;
    }
    double v = 0;
    std::optional<double> compiled = expr_.constant(value, "#define " + name);
    auto ov = std::find_if(overrides_.defines.rbegin(), overrides_.defines.rend(), [&](const DefineOverride& o) { return o.name == name; });
    if (ov != overrides_.defines.rend()) v = ov->value;
    else if (compiled) v = *compiled;
    else return;
    defines_[name] = v;
    prog_.defines.emplace_back(name, v);
  }

  /// `module Apex, Leaf(float)` from column `from` of line: interns the names.
  void declareModules(int line, int from) {
    const std::string& s = scanner_.line(line);
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
        if (name.size() > 1) scanner_.addMultiName(name);
      }
      while (i < n && isSpace(s[i])) ++i;
      if (i < n && s[i] == '(') {  // lpfg-style `module Apex(float)`: the declaration's types are ignored
        while (i < n && s[i] != ')') ++i;
        if (i < n) ++i;
      }
    }
    if (!any && diags().items().empty()) error(line, from, "expected module names after 'module'");
  }

  // ---- pass 2: headers and productions --------------------------------------------------

  /// Pass 2: every line that is not a directive or a declaration.
  void secondPass() {
    Block block = Block::Main;
    for (int line = 1; line <= scanner_.lineCount(); ++line) {
      const std::string& s = scanner_.line(line);
      int b = Scanner::firstNonSpace(s);
      if (b >= static_cast<int>(s.size())) continue;
      if (isEndLsystem(s, b)) {
        Span rest = scanner_.trim(Span{line, b + 10, static_cast<int>(s.size())});
        if (rest.b != rest.e) error(line, rest.b, "unexpected text after 'endlsystem'");
        // In cpfg's notation a later `lsystem:` starts a sub-L-system (notes may stand
        // between); in Sprig's, notes follow and another `lsystem:` is an error.
        if (prog_.dialect == Dialect::Cpfg) {
          if (const int next = nextLsystemHeader(line)) {
            line = next - 1;
            afterEnd_ = true;
            block = Block::Main;
            continue;
          }
          break;
        }
        for (int k = line + 1; k <= scanner_.lineCount(); ++k) {
          const std::string& t = scanner_.line(k);
          const int tb = Scanner::firstNonSpace(t);
          if (tb >= static_cast<int>(t.size())) continue;
          if (auto h = Scanner::headerOf(t, tb); h && h->key == "lsystem") {
            error(k, tb, "several L-systems in one file (cpfg's sub-L-systems) are not supported");
            break;
          }
        }
        break;
      }
      if (s[b] == '#') continue;
      if (isModuleDeclaration(s, b)) continue;
      if (auto bare = bareBlockKeyword(s, b)) {
        handleHeader(line, b, *bare, block);
        continue;
      }
      if (unsupportedHeader(line, b)) continue;
      auto header = Scanner::headerOf(s, b);
      if (header && header->key == "define" && prog_.dialect == Dialect::Cpfg) {
        if (!subs_.empty()) error(line, b, "'define:' in a sub-L-system is not supported (" + std::string(kSubReads) + ")");
        else defineBlock(line, *header);
        continue;
      }
      if (header && std::find(std::begin(kBlockHeaders), std::end(kBlockHeaders), header->key) != std::end(kBlockHeaders)) {
        if (!subs_.empty()) {
          error(line, b, "'" + header->key + ":' in a sub-L-system ('lsystem: " + subs_.back().label +
                             "') is not supported (" + kSubReads + ")");
          continue;
        }
        globalBlock(line, b, *header);
        continue;
      }
      bool known = header && std::find(std::begin(kHeaders), std::end(kHeaders), header->key) != std::end(kHeaders);
      // cpfg: `AXIOM : cond --> succ` is a production of a module named AXIOM (an axiom has no arrow).
      if (known && header->key == "axiom" && prog_.dialect == Dialect::Cpfg && Scanner::findArrow(s).first >= 0) known = false;
      if (known) {
        handleHeader(line, b, *header, block);
        continue;
      }
      auto [arrow, arrowLen] = Scanner::findArrow(s);
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

  /// The line of the first `lsystem:` header after line, or 0.
  int nextLsystemHeader(int line) const {
    for (int k = line + 1; k <= scanner_.lineCount(); ++k) {
      const std::string& t = scanner_.line(k);
      const int tb = Scanner::firstNonSpace(t);
      if (tb >= static_cast<int>(t.size())) continue;
      if (auto h = Scanner::headerOf(t, tb); h && h->key == "lsystem") return k;
    }
    return 0;
  }

  /// cpfg's `lsystem: n` after an `endlsystem` (value at column b of line): starts the
  /// sub-L-system n, whose productions `?(n, scale)` calls apply (docs/GRAMMAR.md).
  void subLsystemHeader(int line, int b, Span value) {
    afterEnd_ = false;
    std::string_view v = scanner_.view(value);
    prog_.subLsystems.emplace_back();
    subs_.push_back({std::string(v), line, b});
    SubLsystem& sub = prog_.subLsystems.back();
    std::tie(sub.loc, sub.sourceLine) = scanner_.locate(line, b);
    auto id = expr_.constant(value, "the number of a sub-L-system");
    if (!id) return;
    if (*id != std::floor(*id)) {
      error(line, value.b, "a sub-L-system's number must be a whole number (cpfg calls it with '?(n, scale)'), got " + formatNumber(*id));
      return;
    }
    sub.id = *id;
    if (prog_.mainLsystemId && *prog_.mainLsystemId == *id)
      error(line, b, "'lsystem: " + std::string(v) + "' has the number of the main L-system");
    for (size_t k = 0; k + 1 < prog_.subLsystems.size(); ++k)
      if (prog_.subLsystems[k].id == *id)
        error(line, b, "'lsystem: " + std::string(v) + "' is defined twice (first at " + scanner_.lineRef(subs_[k].line) + ")");
  }

  /// cpfg's `Start: { statements };` (and `End:`, `StartEach:`, `EndEach:`) at column b of
  /// line: compiled over the global variables, which it may add to.
  void globalBlock(int line, int b, const Header& h) {
    const std::string& s = scanner_.line(line);
    std::string key = h.key;
    key.erase(std::remove(key.begin(), key.end(), ' '), key.end());
    once(key, line, b);
    Span v = scanner_.trim(Span{line, h.valueBegin, static_cast<int>(s.size())});
    if (v.b == v.e || s[v.b] != '{') {
      error(line, v.b, "expected '{ statements }' after '" + s.substr(b, h.valueBegin - b) + "'");
      return;
    }
    int close = matching(line, v.b, v.e, '{', '}');
    if (close < 0) {
      error(line, v.b, "unclosed '{' of a statement block");
      return;
    }
    Span rest = scanner_.trim(Span{line, close + 1, v.e});
    if (rest.b != rest.e && !(rest.e == rest.b + 1 && s[rest.b] == ';')) {
      error(line, rest.b, "unexpected text after the block");
      return;
    }
    CodeRange& out = key == "start" ? prog_.startBlock : key == "end" ? prog_.endBlock
                     : key == "starteach" ? prog_.startEachBlock : prog_.endEachBlock;
    std::vector<std::string> names = prog_.globals;
    expr_.setGlobals(nullptr);  // a block's own registers are the globals
    inGlobalBlock_ = true;
    const bool ok = statementBlock(line, v.b + 1, close, names, out);
    inGlobalBlock_ = false;
    expr_.setGlobals(&prog_.globals);
    if (ok) prog_.globals = names;
  }

  /// cpfg's `define: { array name[d1][d2]... = {v, v, ...}; ... }` (header h on line):
  /// appends the arrays to Program::cpfg. Dimensions and values are constant expressions;
  /// nested braces in an initializer are read as one flat row-major list, and elements
  /// without a value are 0, as in C.
  void defineBlock(int line, const Header& h) {
    const std::string& s = scanner_.line(line);
    Span v = scanner_.trim(Span{line, h.valueBegin, static_cast<int>(s.size())});
    if (v.b == v.e || s[v.b] != '{') {
      error(line, v.b, "expected '{ array name[size] = {...}; }' after 'define:'");
      return;
    }
    const int close = matching(line, v.b, v.e, '{', '}');
    if (close < 0) {
      error(line, v.b, "unclosed '{' of 'define:'");
      return;
    }
    Span rest = scanner_.trim(Span{line, close + 1, v.e});
    if (rest.b != rest.e && !(rest.e == rest.b + 1 && s[rest.b] == ';')) error(line, rest.b, "unexpected text after the block");
    CpfgTables& t = prog_.cpfg;
    int i = v.b + 1;
    for (;;) {
      i = nextNonSpace(line, i, close);
      while (i < close && s[i] == ';') i = nextNonSpace(line, i + 1, close);
      if (i >= close) return;
      if (wordAt(line, i, close) != "array") {
        error(line, i, "expected 'array name[size] = {...};' in 'define:' (cpfg's define block declares arrays)");
        return;
      }
      i = nextNonSpace(line, i + 5, close);
      const std::string name = wordAt(line, i, close);
      if (name.empty()) {
        error(line, i, "expected the array's name after 'array'");
        return;
      }
      const int nameCol = i;
      if (defines_.count(name) || expr_.arrayId(name) >= 0 ||
          std::find(prog_.globals.begin(), prog_.globals.end(), name) != prog_.globals.end()) {
        error(line, i, "'" + name + "' is already a #define, an array or a global variable");
        return;
      }
      CpfgArray a;
      a.name = name;
      a.offset = static_cast<uint32_t>(t.arrayInit.size());
      i = nextNonSpace(line, i + static_cast<int>(name.size()), close);
      double total = 1;
      while (i < close && s[i] == '[') {
        const int end = matching(line, i, close, '[', ']');
        if (end < 0) {
          error(line, i, "unclosed '[' of the array's size");
          return;
        }
        auto n = expr_.constant(scanner_.trim(Span{line, i + 1, end}), "an array's size");
        if (!n) return;
        if (*n != std::floor(*n) || *n < 1) {
          error(line, i + 1, "an array's size must be a whole number of at least 1, got " + formatNumber(*n));
          return;
        }
        total *= *n;
        if (total + static_cast<double>(t.arrayInit.size()) > kMaxArrayElements) {
          error(line, i + 1, "cpfg's arrays have more than " + std::to_string(kMaxArrayElements) + " elements in all (Sprig's limit)");
          return;
        }
        a.dims.push_back(static_cast<int>(*n));
        i = nextNonSpace(line, end + 1, close);
      }
      if (a.dims.empty()) {
        error(line, i, "expected '[size]' after the array's name '" + name + "'");
        return;
      }
      std::vector<double> values(a.size(), 0.0);
      if (i < close && s[i] == '=') {
        i = nextNonSpace(line, i + 1, close);
        if (i >= close || s[i] != '{') {
          error(line, i, "expected '{' and the array's values after '='");
          return;
        }
        const int end = matching(line, i, close, '{', '}');
        if (end < 0) {
          error(line, i, "unclosed '{' of the array's values");
          return;
        }
        size_t count = 0;
        int item = i + 1, depth = 0;
        for (int k = i + 1; k <= end; ++k) {
          const char c = s[k];
          if (c == '(') ++depth;
          if (c == ')') --depth;
          if (k < end && depth > 0) continue;
          if (k == end || c == ',' || c == '{' || c == '}') {
            Span value = scanner_.trim(Span{line, item, k});
            item = k + 1;
            if (value.b == value.e) continue;
            if (count == values.size()) {
              error(line, value.b, "too many values for the array '" + name + "' (it has " + std::to_string(values.size()) + " elements)");
              return;
            }
            auto x = expr_.constant(value, "an array's value");
            if (!x) return;
            values[count++] = *x;
          }
        }
        i = end + 1;
      }
      i = nextNonSpace(line, i, close);
      if (i < close && s[i] != ';') {
        error(line, i, "expected ';' after the declaration of the array '" + name + "'");
        return;
      }
      (void)nameCol;
      t.arrays.push_back(std::move(a));
      t.arrayInit.insert(t.arrayInit.end(), values.begin(), values.end());
    }
  }

  /// Reports cpfg's headers Sprig does not implement (`Start:`, `define:`, `ring lsystem`)
  /// at column b of line; true when the line was one.
  bool unsupportedHeader(int line, int b) {
    const std::string& s = scanner_.line(line);
    auto header = Scanner::headerOf(s, b);
    std::string words;
    for (int i = b; i < static_cast<int>(s.size()) && words.size() < 13; ++i)
      if (!isSpace(s[i])) words += static_cast<char>(std::tolower(static_cast<unsigned char>(s[i])));
    const bool ring = (header && header->key == "ring lsystem") ||
                      ((words == "ringlsystem" || words == "ringlsystem:") && Scanner::findArrow(s).first < 0);
    if (!ring) return false;
    if (prog_.dialect == Dialect::Cpfg && subs_.empty()) {
      // cpfg's ring L-system (3.1.1): context matching joins the string's ends.
      once("ring lsystem", line, b);
      prog_.ring = true;
    } else {
      error(line, b, std::string("cpfg's 'ring lsystem' (ring L-system) is supported only for the main L-system of a .l file"));
    }
    return true;
  }

  /// Records header key at line (per L-system: a sub-L-system has its own); a second one is
  /// an error.
  void once(const std::string& key, int line, int col) {
    auto [it, inserted] = seen_.emplace(scoped(key), line);
    if (!inserted) error(line, col, "duplicate '" + key + ":' (first at " + scanner_.lineRef(it->second) + ")");
  }

  /// key in seen_ for the L-system being read (the main one's keys are bare).
  std::string scoped(const std::string& key) const {
    return subs_.empty() ? key : "lsystem " + std::to_string(subs_.size()) + ": " + key;
  }
  /// The decomposition or interpretation rules of the L-system being read.
  RuleSet& blockRules(Block block) {
    if (!subs_.empty()) {
      SubLsystem& sub = prog_.subLsystems.back();
      return block == Block::Main ? sub.productions : block == Block::Decomposition ? sub.decomposition : sub.interpretation;
    }
    return block == Block::Main ? prog_.productions : block == Block::Decomposition ? prog_.decomposition : prog_.interpretation;
  }

  /// `axiom: MODULES`: checked module by module; finish() reads it again once the seed is known.
  void axiomHeader(int line, int b, Span value) {
    once("axiom", line, b);
    // Streamed module by module, never stored: an axiom may hold millions of modules.
    // finish() tokenizes the line again to append them, once the seed is known.
    BracketState brackets;
    WordLint words;
    if (value.b == value.e) error(line, value.b, "the axiom is empty");
    else if (scanner_.tokenizeModules(line, value.b, value.e, [&](const RawModule& m) {
               if (m.name == "@L") error(line, m.col, kLabelOutsideInterpretation);
               bracketModule(line, m, brackets, "the axiom");
               noteWritten(line, m);
               lintWord(line, words, &m);
             }) && bracketEnd(line, brackets, "the axiom")) {
      lintWord(line, words, nullptr);
      axiomSpan_ = value;
      axiomLine_ = line;
      std::tie(prog_.axiomLoc, prog_.axiomLine) = scanner_.locate(line, b);
    }
  }

  /// `ignore:` or `consider:` (key): the symbols context matching skips or sees.
  void contextListHeader(int line, int b, const std::string& key, Span value, Block block) {
    once(key, line, b);
    if (block != Block::Main) error(line, b, "'" + key + ":' belongs before the decomposition and interpretation blocks");
    std::vector<RawModule> mods;
    if (scanner_.tokenizeModules(line, value.b, value.e, mods)) {
      for (const RawModule& m : mods) {
        if (m.hasParens) {
          error(line, m.col, "'" + key + ":' lists symbols without parameters");
        } else if ((m.name == "[" || m.name == "]") && prog_.dialect != Dialect::Cpfg) {
          // Sprig's notation: context matching always follows brackets (lpfg's rule).
          if (key == "ignore")
            error(line, m.col, "brackets cannot be ignored in Sprig's notation: context matching always follows them");
        } else {
          std::vector<SymbolId>& list = subs_.empty() ? (key == "ignore" ? ignoreList_ : considerList_)
                                                      : (key == "ignore" ? subs_.back().ignoreList : subs_.back().considerList);
          list.push_back(prog_.symbols.intern(m.name));
        }
      }
    }
    const std::string ign = scoped("ignore"), con = scoped("consider");
    if (seen_.count(ign) && seen_.count(con) && key == (seen_[ign] < seen_[con] ? "consider" : "ignore"))
      error(line, b, "use either 'ignore:' or 'consider:', not both");
  }

  /// A known header h at column b of line (`decomposition:` and `interpretation:` switch block).
  void handleHeader(int line, int b, const Header& h, Block& block) {
    const std::string& s = scanner_.line(line);
    Span value = scanner_.trim(Span{line, h.valueBegin, static_cast<int>(s.size())});
    std::string_view v = scanner_.view(value);
    if (h.key == "lsystem" && afterEnd_) {
      subLsystemHeader(line, b, value);
      return;
    }
    if (!subs_.empty()) {
      // cpfg reads a sub-L-system's productions, decomposition and interpretation rules and
      // its ignore: or consider: list; its own derivation length and axiom matter only when
      // it is the main one (lsys_input.y), so Sprig skips them too.
      static const char* const kSubHeaders[] = {"ignore", "consider", "decomposition", "interpretation", "homomorphism", "maximum depth"};
      if (h.key == "derivation length" || h.key == "axiom") return;
      if (std::find(std::begin(kSubHeaders), std::end(kSubHeaders), h.key) == std::end(kSubHeaders)) {
        error(line, b, "'" + h.key + ":' in a sub-L-system ('lsystem: " + subs_.back().label +
                           "') is not supported (" + kSubReads + ")");
        return;
      }
    }
    if (h.key == "lsystem") {
      if (seen_.count("lsystem")) {
        error(line, b, "several L-systems in one file (cpfg's sub-L-systems) are not supported (the first is at line " +
                           std::to_string(seen_["lsystem"]) + ")");
        return;
      }
      once(h.key, line, b);
      prog_.name = std::string(v);
      if (prog_.dialect == Dialect::Cpfg) {  // its number, for `?(n, s)` calls back into it
        double id = 0;
        auto r = std::from_chars(v.data(), v.data() + v.size(), id);
        if (!v.empty() && r.ec == std::errc() && r.ptr == v.data() + v.size()) prog_.mainLsystemId = id;
      }
    } else if (h.key == "derivation length") {
      once(h.key, line, b);
      if (auto d = expr_.constant(value, "derivation length")) {
        if (*d < 0 || *d != std::floor(*d) || *d > 1e6) {
          error(line, value.b, "derivation length must be a whole number from 0 to 1000000, got " + formatNumber(*d));
        } else {
          prog_.derivationLength = static_cast<int>(*d);
          std::tie(prog_.lengthLoc, prog_.lengthLine) = scanner_.locate(line, b);
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
      prog_.hasSeed = true;
    } else if (h.key == "angle") {
      once(h.key, line, b);
      if (auto d = expr_.constant(value, "angle")) {
        prog_.hasAngle = true;
        prog_.angleDeg = *d;
      }
    } else if (h.key == "axiom") {
      axiomHeader(line, b, value);
    } else if (h.key == "ignore" || h.key == "consider") {
      contextListHeader(line, b, h.key, value, block);
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
      if (auto d = expr_.constant(value, "maximum depth")) {
        if (*d < 1 || *d != std::floor(*d) || *d > 1e6)
          error(line, value.b, "maximum depth must be a whole number from 1 to 1000000, got " + formatNumber(*d));
        else
          blockRules(block).maxDepth = static_cast<int>(*d);
      }
    }
  }

  static bool isQuery(std::string_view name) {
    return name == "?P" || name == "?H" || name == "?L" || name == "?U" || name == "?E";
  }
  /// cpfg fills a query module of an interpretation rule in the interpreted copy of the
  /// string, where no production reads it; Sprig refuses it rather than ignore it.
  static std::string queryInInterpretation(std::string_view name) {
    return "cpfg's query module '" + std::string(name) +
           "' in an interpretation rule is not supported (its values would be lost with the interpreted string)";
  }

  /// The production of line (from column b, its arrow at `arrow`), compiled into block's RuleSet.
  void parseProduction(int line, int b, int arrow, int arrowLen, Block block) {
    const std::string& s = scanner_.line(line);
    statementBlock_ = block;
    int n = static_cast<int>(s.size());
    Production p;
    size_t diagsBefore = diags().items().size();
    // Split `lc < pred > rc : cond` and `succ : weight`.
    int colon = scanner_.findTop(line, b, arrow, ':');
    int headEnd = colon >= 0 ? colon : arrow;
    Span lc{line, b, b}, pred{line, b, headEnd}, rc{line, headEnd, headEnd};
    int lt = scanner_.findTop(line, b, headEnd, '<');
    if (lt >= 0) {
      lc = Span{line, b, lt};
      pred.b = lt + 1;
    }
    int gt = scanner_.findTop(line, pred.b, headEnd, '>');
    if (gt >= 0) {
      rc = Span{line, gt + 1, headEnd};
      pred.e = gt;
    }
    Span cond{line, colon >= 0 ? colon + 1 : arrow, arrow};
    int succBegin = arrow + arrowLen;
    int wcolon = scanner_.findTopLast(line, succBegin, n, ':');
    Span succ{line, succBegin, wcolon >= 0 ? wcolon : n};
    Span weight{line, wcolon >= 0 ? wcolon + 1 : n, n};

    std::vector<std::string> varNames;
    // Predecessor.
    pred = scanner_.trim(pred);
    std::vector<RawModule> predMods;
    if (pred.b == pred.e) {
      error(line, pred.b, "missing predecessor before '" + s.substr(arrow, arrowLen) + "'");
      return;
    }
    if (prog_.dialect == Dialect::Cpfg && scanner_.view(pred) == kGenCylPrefix) {
      // cpfg's `@G`: the modules '@' and 'G' that begin every generalized-cylinder command
      // (expandGenCylRules).
      if (block != Block::Interpretation) {
        error(line, pred.b, "cpfg's predecessor '@G' (the '@' and 'G' of the generalized-cylinder commands) is supported only in an interpretation (homomorphism) rule");
        return;
      }
      predMods.push_back(RawModule{kGenCylPrefix, pred.b, {}, false});
    } else {
      if (!scanner_.tokenizeModules(line, pred.b, pred.e, predMods)) return;
      lintWords(line, predMods);
    }
    if (predMods.empty()) {
      error(line, pred.b, "a predecessor must be a single module");
      return;
    }
    // cpfg matches a predecessor module by module, brackets included (`[f(y)P(r)] --> *`);
    // Sprig's notation keeps brackets out of predecessors.
    for (const RawModule& m : predMods)
      if ((m.name == "[" || m.name == "]") && prog_.dialect != Dialect::Cpfg) {
        error(line, m.col, "a bracket cannot be a predecessor");
        return;
      }
    for (const RawModule& m : predMods)
      if (block == Block::Interpretation && isQuery(m.name)) {
        error(line, m.col, queryInInterpretation(m.name));
        return;
      }
    // Contexts (textual order: left, predecessor, right).
    lc = scanner_.trim(lc);
    rc = scanner_.trim(rc);
    if (lc.b != lc.e && !scanner_.isStar(lc)) {
      if (block != Block::Main) error(line, lc.b, std::string("context is not allowed in ") + blockName(block) + " rules");
      else p.left = pattern(lc, varNames, true);
    }
    std::tie(p.loc, p.sourceLine) = scanner_.locate(line, predMods[0].col);
    p.text = std::string(scanner_.view(pred));
    p.predecessor = prog_.symbols.intern(predMods[0].name);
    p.predFirstVar = static_cast<uint16_t>(varNames.size());
    p.predParams = static_cast<uint16_t>(formals(predMods[0], varNames));
    arityUses_.push_back({predMods[0].name, p.predParams, line, predMods[0].col, scanner_.moduleText(line, predMods[0]), false});
    for (size_t k = 1; k < predMods.size(); ++k) {
      PatternItem it;
      it.symbol = prog_.symbols.intern(predMods[k].name);
      it.firstVar = static_cast<uint16_t>(varNames.size());
      it.paramCount = static_cast<uint16_t>(formals(predMods[k], varNames));
      arityUses_.push_back({predMods[k].name, it.paramCount, line, predMods[k].col, scanner_.moduleText(line, predMods[k]), false});
      p.predRest.push_back(it);
    }
    if (rc.b != rc.e && !scanner_.isStar(rc)) {
      if (block != Block::Main) error(line, rc.b, std::string("context is not allowed in ") + blockName(block) + " rules");
      else p.right = pattern(rc, varNames, false);
    }
    if (diags().items().size() != diagsBefore) return;
    expr_.clearRandom();
    // Condition, with cpfg's statements around it: `{ before } cond { after }`.
    cond = scanner_.trim(cond);
    if (scanner_.findTop(line, cond.b, cond.e, '{') >= 0 && !productionStatements(line, cond, varNames, p)) return;
    if (colon >= 0 && cond.b == cond.e && !p.hasStatements()) error(line, colon, "missing condition after ':' (write '*' for none)");
    else if (cond.b != cond.e && !scanner_.isStar(cond)) {
      size_t before = prog_.code.size();
      if (expr_.compile(cond, varNames, "condition")) {
        if (prog_.code.size() == before + 1 && prog_.code.back().op == Op::Const && prog_.code.back().c != 0) prog_.code.pop_back();
        else p.condition = CodeRange{static_cast<uint32_t>(before), static_cast<uint32_t>(prog_.code.size())};
      }
    }
    successor(line, scanner_.trim(succ), block, varNames, p);
    // Weight.
    if (wcolon >= 0) {
      weight = scanner_.trim(weight);
      if (weight.b == weight.e) error(line, wcolon, "missing weight after ':'");
      else if (auto w = expr_.constant(weight, "weight")) {
        if (*w < 0) error(line, weight.b, "a weight must not be negative, got " + formatNumber(*w));
        p.stochastic = true;
        p.weight = *w;
      }
    }
    p.usesRandom = expr_.usesRandom();
    blockRules(block).productions.push_back(std::move(p));
  }

  /// A production's successor `succ` (trimmed), compiled into p's modules and arguments.
  void successor(int line, Span succ, Block block, const std::vector<std::string>& varNames, Production& p) {
    if (succ.b == succ.e) {
      error(line, succ.b, "missing successor (write '*' for the empty string)");
      return;
    }
    if (scanner_.isStar(succ)) return;
    std::vector<RawModule> mods;
    if (!scanner_.tokenizeModules(line, succ.b, succ.e, mods) || !checkBrackets(line, mods, "the successor")) return;
    noteWritten(line, mods);
    lintWords(line, mods);
    for (const RawModule& m : mods) {
      if (block == Block::Interpretation && isQuery(m.name)) error(line, m.col, queryInInterpretation(m.name));
      const bool label = m.name == "@L";
      if (label && block != Block::Interpretation) error(line, m.col, kLabelOutsideInterpretation);
      SuccModule sm;
      sm.symbol = prog_.symbols.intern(m.name);
      sm.firstArg = static_cast<uint32_t>(p.args.size());
      sm.argCount = static_cast<uint16_t>(m.args.size());
      for (const Span& a : m.args) {
        const Span t = scanner_.trim(a);
        if (label && t.b < t.e && scanner_.line(line)[t.b] == '"') {
          // @L's format: its number among the program's strings (cpfg stores it so).
          p.args.push_back(Arg{ArgKind::Const, 0, static_cast<double>(prog_.strings.size()), {}});
          prog_.strings.push_back(scanner_.line(line).substr(t.b, t.e - t.b));
          continue;
        }
        p.args.push_back(expr_.compileArg(t, varNames));
      }
      p.successor.push_back(sm);
    }
  }

  // ---- cpfg's statements ---------------------------------------------------------------

  /// Index of the `close` matching the `open` at i of line (nesting counted), or -1.
  int matching(int line, int i, int e, char open, char close) {
    const std::string& s = scanner_.line(line);
    int depth = 0;
    for (int k = i; k < e; ++k) {
      if (s[k] == open) ++depth;
      else if (s[k] == close && --depth == 0) return k;
    }
    return -1;
  }

  /// Splits `{ before } cond { after }` (sp, the text between the production's `:` and
  /// its arrow) and compiles the blocks into p; cond is narrowed to the condition. Locals
  /// get registers after the formal parameters in varNames. False after an error.
  bool productionStatements(int line, Span& cond, std::vector<std::string>& varNames, Production& p) {
    const std::string& s = scanner_.line(line);
    const size_t formalsCount = varNames.size();
    int i = cond.b;
    if (s[i] == '{') {
      int close = matching(line, i, cond.e, '{', '}');
      if (close < 0) {
        error(line, i, "unclosed '{' of a statement block");
        return false;
      }
      if (!statementBlock(line, i + 1, close, varNames, p.before)) return false;
      i = close + 1;
    }
    int brace = scanner_.findTop(line, i, cond.e, '{');
    Span c = scanner_.trim(Span{line, i, brace >= 0 ? brace : cond.e});
    if (brace >= 0) {
      int close = matching(line, brace, cond.e, '{', '}');
      if (close < 0) {
        error(line, brace, "unclosed '{' of a statement block");
        return false;
      }
      if (!statementBlock(line, brace + 1, close, varNames, p.after)) return false;
      Span rest = scanner_.trim(Span{line, close + 1, cond.e});
      if (rest.b != rest.e) {
        error(line, rest.b, "unexpected text after the statements (expected the arrow '-->')");
        return false;
      }
    }
    if (c.b == c.e) c = Span{line, c.b, c.b};
    cond = c;
    p.localFirst = static_cast<uint16_t>(formalsCount);
    p.localCount = static_cast<uint16_t>(varNames.size() - formalsCount);
    return true;
  }

  /// Compiles the statements of line[b, e) (inside one `{ }`) into a block of its own code.
  bool statementBlock(int line, int b, int e, std::vector<std::string>& varNames, CodeRange& out) {
    const uint32_t begin = static_cast<uint32_t>(prog_.code.size());
    if (!statementList(line, b, e, varNames, begin)) {
      prog_.code.resize(begin);
      return false;
    }
    if (prog_.code.size() == begin) return true;  // `{ }`
    out = CodeRange{begin, static_cast<uint32_t>(prog_.code.size())};
    return true;
  }

  /// Appends a jump (op Jz or Jmp) to target (counted from base); returns its index.
  size_t jump(Op op, uint32_t base, double target) {
    Instr in;
    in.op = op;
    in.c = target - base;
    prog_.code.push_back(in);
    return prog_.code.size() - 1;
  }
  void patch(size_t at, uint32_t base) { prog_.code[at].c = static_cast<double>(prog_.code.size() - base); }

  /// The first column from i of line[.., e) that is not white space (e when none).
  int nextNonSpace(int line, int i, int e) const {
    const std::string& s = scanner_.line(line);
    while (i < e && isSpace(s[i])) ++i;
    return i;
  }

  /// The word (identifier) at i of line, or empty.
  std::string wordAt(int line, int i, int e) const {
    const std::string& s = scanner_.line(line);
    int j = i;
    if (j < e && isIdentStart(s[j]))
      while (j < e && isIdentChar(s[j])) ++j;
    return s.substr(i, j - i);
  }

  /// `( expr )` at i: compiles expr; returns the index after `)`, or -1 after an error.
  int parenthesized(int line, int i, int e, const std::vector<std::string>& varNames, const char* what) {
    const std::string& s = scanner_.line(line);
    while (i < e && isSpace(s[i])) ++i;
    if (i >= e || s[i] != '(') {
      error(line, i, std::string("expected '(' after '") + what + "'");
      return -1;
    }
    int close = matching(line, i, e, '(', ')');
    if (close < 0) {
      error(line, i, "missing ')'");
      return -1;
    }
    Span c = scanner_.trim(Span{line, i + 1, close});
    if (c.b == c.e) {
      error(line, i, std::string("missing condition of '") + what + "'");
      return -1;
    }
    if (!expr_.compile(c, varNames, "condition")) return -1;
    return close + 1;
  }

  /// `{ statements }` at i: compiles them; returns the index after `}`, or -1.
  int braced(int line, int i, int e, std::vector<std::string>& varNames, uint32_t base, const char* after) {
    const std::string& s = scanner_.line(line);
    while (i < e && isSpace(s[i])) ++i;
    if (i >= e || s[i] != '{') {
      error(line, i, std::string("expected '{' after '") + after + "' (cpfg requires braces)");
      return -1;
    }
    int close = matching(line, i, e, '{', '}');
    if (close < 0) {
      error(line, i, "unclosed '{'");
      return -1;
    }
    if (!statementList(line, i + 1, close, varNames, base)) return -1;
    return close + 1;
  }

  /// Statements `x = expr;`, `if (c) {...} [else {...}]`, `while (c) {...}`,
  /// `do {...} while (c);` of line[b, e) (cpfg reference manual, 3.2), appended to the code.
  /// cpfg's `printf("format", values...);` at column at of line (its `(` at open): compiles
  /// the values and an Op::Printf; returns the column after its `;`, or -1 after an error.
  int printfStatement(int line, int at, int open, int e, std::vector<std::string>& varNames, const std::string& fn = "printf",
                      Op op = Op::Printf) {
    const std::string& s = scanner_.line(line);
    int q = nextNonSpace(line, open + 1, e);
    if (q >= e || s[q] != '"') {
      error(line, q, fn + "'s " + (op == Op::Printf ? "first" : "second") + " argument must be a format in double quotes");
      return -1;
    }
    std::string format;
    int j = q + 1;
    for (; j < e && s[j] != '"'; ++j) {
      if (s[j] == '\\' && j + 1 < e) {
        const char c = s[++j];
        format += c == 'n' ? '\n' : c == 't' ? '\t' : c;
      } else {
        format += s[j];
      }
    }
    if (j >= e) {
      error(line, q, "unterminated format string of " + fn);
      return -1;
    }
    // Conversions: numbers only (cpfg's values are numbers), one per value.
    int conversions = 0;
    for (size_t f = 0; f < format.size(); ++f) {
      if (format[f] != '%') continue;
      if (f + 1 < format.size() && format[f + 1] == '%') {
        ++f;
        continue;
      }
      size_t g = f + 1;
      while (g < format.size() && std::string_view("-+ #0123456789.hlL").find(format[g]) != std::string_view::npos) ++g;
      if (g >= format.size() || std::string_view("diouxXcfFeEgGaA").find(format[g]) == std::string_view::npos) {
        error(line, q, fn + "'s conversion '" + format.substr(f, g + 1 - f) +
                           "' is not supported (only numbers: %d %i %o %u %x %c %f %e %g %a)");
        return -1;
      }
      ++conversions;
      f = g;
    }
    // The values: top-level commas up to the call's `)`.
    int close = -1, depth = 0;
    for (int k = j + 1; k < e; ++k) {
      if (s[k] == '(') ++depth;
      if (s[k] == ')' && depth-- == 0) {
        close = k;
        break;
      }
    }
    if (close < 0) {
      error(line, open, "missing ')' after the arguments of " + fn);
      return -1;
    }
    int values = 0;
    int k = nextNonSpace(line, j + 1, close);
    if (k < close && s[k] != ',') {
      error(line, k, "expected ',' or ')' after " + fn + "'s format");
      return -1;
    }
    while (k < close) {
      int next = scanner_.findTop(line, k + 1, close, ',');
      if (next < 0) next = close;
      if (!expr_.compile(scanner_.trim(Span{line, k + 1, next}), varNames, (fn + " value").c_str())) return -1;
      ++values;
      k = next;
    }
    if (values != conversions) {
      error(line, at, fn + "'s format has " + std::to_string(conversions) + " conversion(s) for " +
                          std::to_string(values) + " value(s)");
      return -1;
    }
    if (values > 8) {
      error(line, at, fn + " with more than 8 values is not supported");
      return -1;
    }
    int semi = nextNonSpace(line, close + 1, e);
    if (semi >= e || s[semi] != ';') {
      error(line, at, "missing ';' after the call of '" + fn + "' (cpfg requires one after every statement)");
      return -1;
    }
    Instr pr;
    pr.op = op;
    pr.var = static_cast<uint16_t>(prog_.strings.size());
    pr.c = values;
    prog_.strings.push_back(format);
    prog_.code.push_back(pr);
    return semi + 1;
  }

  /// cpfg's files (userfiles.cpp), in the Start/StartEach/EndEach/End blocks of a .l file:
  /// `f = fopen("name", "w" or "a");`, `fprintf(f, "format", values...);`, `fflush(f);`,
  /// `fclose(f);`. Whether the statement word at `at` may be compiled here (else an error).
  bool fileCallAllowed(int line, int at, const std::string& word) {
    if (inGlobalBlock_) return true;
    error(line, at, "cpfg's function '" + word + "' is supported only in the Start:, StartEach:, EndEach: and End: blocks of a .l file");
    return false;
  }

  /// `fprintf(f, "format", values...);` (its `(` at open): the index, then as printf.
  int fprintfStatement(int line, int at, int open, int e, std::vector<std::string>& varNames) {
    if (!fileCallAllowed(line, at, "fprintf")) return -1;
    const int comma = scanner_.findTop(line, open + 1, e, ',');
    if (comma < 0) {
      error(line, open, "fprintf takes a file, a format and values");
      return -1;
    }
    if (!expr_.compile(scanner_.trim(Span{line, open + 1, comma}), varNames, "fprintf file")) return -1;
    return printfStatement(line, at, comma, e, varNames, "fprintf", Op::Fprintf);
  }

  /// `fflush(f);` or `fclose(f);` (its `(` at open).
  int fileStatement(int line, int at, int open, int e, const std::string& word, std::vector<std::string>& varNames) {
    if (!fileCallAllowed(line, at, word)) return -1;
    const int close = matching(line, open, e, '(', ')');
    const int semi = close < 0 ? -1 : nextNonSpace(line, close + 1, e);
    if (close < 0 || semi >= e || scanner_.line(line)[semi] != ';') {
      error(line, at, "missing ';' after the call of '" + word + "' (cpfg requires one after every statement)");
      return -1;
    }
    if (!expr_.compile(scanner_.trim(Span{line, open + 1, close}), varNames, (word + " file").c_str())) return -1;
    Instr in;
    in.op = word == "fflush" ? Op::Fflush : Op::Fclose;
    prog_.code.push_back(in);
    return semi + 1;
  }

  /// The value `fopen("name", "mode")` of an assignment: Op::Fopen with the name and mode in
  /// Program::strings. Names are plain file names (the grammar's folder); modes "w" and "a".
  bool fopenValue(Span value) {
    const int line = value.line;
    const std::string& s = scanner_.line(line);
    auto literal = [&](int& i, const char* what) -> std::optional<std::string> {
      i = nextNonSpace(line, i, value.e);
      const size_t q = i < value.e && s[i] == '"' ? s.find('"', i + 1) : std::string::npos;
      if (q == std::string::npos || static_cast<int>(q) >= value.e) {
        error(line, i, std::string("fopen's ") + what + " must be in double quotes");
        return std::nullopt;
      }
      std::string t = s.substr(i + 1, q - i - 1);
      i = static_cast<int>(q) + 1;
      return t;
    };
    int i = nextNonSpace(line, value.b + 5, value.e) + 1;  // past "fopen("
    const int nameAt = nextNonSpace(line, i, value.e);
    auto name = literal(i, "file name");
    if (!name) return false;
    i = nextNonSpace(line, i, value.e);
    if (i >= value.e || s[i] != ',') {
      error(line, i, "fopen takes a file name and a mode");
      return false;
    }
    const int modeAt = nextNonSpace(line, i + 1, value.e);
    ++i;
    auto mode = literal(i, "mode");
    if (!mode) return false;
    i = nextNonSpace(line, i, value.e);
    if (i >= value.e || s[i] != ')' || nextNonSpace(line, i + 1, value.e) < value.e) {
      error(line, i, "expected ')' after fopen's mode (fopen's value is assigned alone)");
      return false;
    }
    if (name->empty() || *name == "." || *name == ".." || name->find_first_of("/\\") != std::string::npos) {
      error(line, nameAt, "fopen's file '" + *name + "' must be a plain file name: Sprig writes only in the grammar's folder");
      return false;
    }
    if (*mode != "w" && *mode != "a") {
      error(line, modeAt, "cpfg's fopen mode '" + *mode + "' is not supported (only \"w\" and \"a\": Sprig writes files, fscanf is not supported)");
      return false;
    }
    Instr in;
    in.op = Op::Fopen;
    in.var = static_cast<uint16_t>(prog_.strings.size());
    prog_.strings.push_back(*name);
    prog_.strings.push_back(*mode);
    prog_.code.push_back(in);
    return true;
  }

  /// A statement list `b..e` of a block, a production's or a function's body: assignments,
  /// `if`/`else`, `while`, `do ... while`, calls and cpfg's expression statements.
  bool statementList(int line, int b, int e, std::vector<std::string>& varNames, uint32_t base) {
    const std::string& s = scanner_.line(line);
    int i = b;
    for (;;) {
      while (i < e && (isSpace(s[i]) || s[i] == ';')) ++i;
      if (i >= e) return true;
      const std::string word = wordAt(line, i, e);
      if (word.empty()) {
        error(line, i, std::string("expected a statement (an assignment, 'if', 'while' or 'do'), got '") + s[i] + "'");
        return false;
      }
      const int at = i;
      i += static_cast<int>(word.size());
      const int k = nextNonSpace(line, i, e);
      if (word == "if") {
        i = ifStatement(line, i, e, varNames, base);
      } else if (word == "while") {
        i = whileStatement(line, i, e, varNames, base);
      } else if (word == "do") {
        i = doStatement(line, i, e, varNames, base);
      } else if (k < e && s[k] == '(' && word == "printf") {
        i = printfStatement(line, at, k, e, varNames);
      } else if (k < e && s[k] == '(' && word == "fprintf" && prog_.dialect == Dialect::Cpfg) {
        i = fprintfStatement(line, at, k, e, varNames);
      } else if (k < e && s[k] == '(' && (word == "fflush" || word == "fclose") && prog_.dialect == Dialect::Cpfg) {
        i = fileStatement(line, at, k, e, word, varNames);
      } else if (k < e && s[k] == '(') {
        i = callStatement(line, at, e, word, varNames, base);
      } else if (k < e && s[k] == '[' && expr_.arrayId(word) >= 0) {
        i = elementAssignment(line, at, k, e, word, varNames);
      } else {
        i = assignment(line, at, i, e, word, varNames, base);
      }
      if (i < 0) return false;
    }
  }

  /// `if (...) { ... } [else { ... }]` from after `if`; the index after it, or -1.
  int ifStatement(int line, int i, int e, std::vector<std::string>& varNames, uint32_t base) {
    const std::string& s = scanner_.line(line);
    if ((i = parenthesized(line, i, e, varNames, "if")) < 0) return -1;
    size_t jz = jump(Op::Jz, base, 0);
    if ((i = braced(line, i, e, varNames, base, "if (...)")) < 0) return -1;
    int k = i;
    while (k < e && isSpace(s[k])) ++k;
    if (wordAt(line, k, e) != "else") {
      patch(jz, base);
      return i;
    }
    size_t jmp = jump(Op::Jmp, base, 0);
    patch(jz, base);
    if ((i = braced(line, k + 4, e, varNames, base, "else")) < 0) return -1;
    patch(jmp, base);
    return i;
  }

  /// `while (...) { ... }` from after `while`; the index after it, or -1.
  int whileStatement(int line, int i, int e, std::vector<std::string>& varNames, uint32_t base) {
    const double top = static_cast<double>(prog_.code.size());
    if ((i = parenthesized(line, i, e, varNames, "while")) < 0) return -1;
    size_t jz = jump(Op::Jz, base, 0);
    if ((i = braced(line, i, e, varNames, base, "while (...)")) < 0) return -1;
    jump(Op::Jmp, base, top);
    patch(jz, base);
    return i;
  }

  /// `do { ... } while (...)` from after `do`; the index after it, or -1.
  int doStatement(int line, int i, int e, std::vector<std::string>& varNames, uint32_t base) {
    const std::string& s = scanner_.line(line);
    const double top = static_cast<double>(prog_.code.size());
    if ((i = braced(line, i, e, varNames, base, "do")) < 0) return -1;
    while (i < e && isSpace(s[i])) ++i;
    if (wordAt(line, i, e) != "while") {
      error(line, i, "expected 'while (...)' after 'do { ... }'");
      return -1;
    }
    if ((i = parenthesized(line, i + 5, e, varNames, "while")) < 0) return -1;
    Instr notOp;
    notOp.op = Op::Not;
    prog_.code.push_back(notOp);
    jump(Op::Jz, base, top);
    return i;
  }

  /// A call alone, `f(...);` (cpfg's srand, ...), starting at `at`: its value is dropped.
  int callStatement(int line, int at, int e, const std::string& word, std::vector<std::string>& varNames, uint32_t base) {
    const int end = scanner_.findTop(line, at, e, ';');
    if (end < 0) {
      error(line, at, "missing ';' after the call of '" + word + "' (cpfg requires one after every statement)");
      return -1;
    }
    // cpfg's srand and stop are statements of their own (Op::Srand, Op::Stop).
    const bool effectCall = word == "srand" || word == "stop";
    if (effectCall)
      expr_.allowEffects(inGlobalBlock_ || prog_.dialect == Dialect::Cpfg,
                         inGlobalBlock_ || statementBlock_ != Block::Interpretation,
                         "cpfg's function 'stop' in an interpretation rule is not supported (the derivation has ended "
                         "when the string is interpreted): call it in a production or a Start/EndEach block");
    const bool compiled = expr_.compile(scanner_.trim(Span{line, at, end}), varNames, "statement");
    if (effectCall) expr_.allowEffects(false, false, "cpfg's function 'stop' is supported only as a statement ('stop(1);')");
    if (!compiled) return -1;
    jump(Op::Jz, base, static_cast<double>(prog_.code.size() + 1));  // pops the value, jumps to the next instruction
    return end + 1;
  }

  /// Assignment to an element of cpfg's array, `name[i][j] = expression;`, whose first `[`
  /// is at `open`.
  int elementAssignment(int line, int at, int open, int e, const std::string& word, std::vector<std::string>& varNames) {
    const std::string& s = scanner_.line(line);
    int eq = open;
    while (eq < e && s[eq] == '[') {
      const int end = matching(line, eq, e, '[', ']');
      if (end < 0) {
        error(line, eq, "unclosed '['");
        return -1;
      }
      eq = nextNonSpace(line, end + 1, e);
    }
    if (eq >= e || s[eq] != '=' || (eq + 1 < e && s[eq + 1] == '=')) {
      error(line, eq, "expected '=' after '" + word + "[...]'");
      return -1;
    }
    const int end = scanner_.findTop(line, eq + 1, e, ';');
    if (end < 0) {
      error(line, at, "missing ';' after the assignment to '" + word + "[...]' (cpfg requires one after every statement)");
      return -1;
    }
    const Span value = scanner_.trim(Span{line, eq + 1, end});
    if (value.b == value.e) {
      error(line, eq, "missing value after '" + word + "[...] ='");
      return -1;
    }
    auto a = expr_.compileElement(scanner_.trim(Span{line, at, eq}), varNames);
    if (!a) return -1;
    if (!expr_.compile(value, varNames, "value")) return -1;
    Instr store;
    store.op = Op::ArrayStore;
    store.var = static_cast<uint16_t>(*a);
    prog_.code.push_back(store);
    return end + 1;
  }

  /// `name = expression;` (or, in a .l file, an expression statement whose value is
  /// dropped), `name` at `at` and `i` just after it; the index after the `;`, or -1.
  int assignment(int line, int at, int i, int e, const std::string& word, std::vector<std::string>& varNames,
                 uint32_t base) {
    const std::string& s = scanner_.line(line);
    while (i < e && isSpace(s[i])) ++i;
    const bool assign = i < e && s[i] == '=' && !(i + 1 < e && s[i + 1] == '=');
    const bool compound = i + 1 < e && std::string_view("+-*/%").find(s[i]) != std::string_view::npos && s[i + 1] == '=';
    if (!assign && !compound && prog_.dialect == Dialect::Cpfg) {
      // cpfg's expression statement (`roll - roll/L0;` in vlab's paintbrush): evaluated,
      // its value dropped.
      const int end = scanner_.findTop(line, at, e, ';');
      if (end < 0) {
        error(line, at, "missing ';' after the statement '" + word + " ...' (cpfg requires one after every statement)");
        return -1;
      }
      if (!expr_.compile(scanner_.trim(Span{line, at, end}), varNames, "statement")) return -1;
      jump(Op::Jz, base, static_cast<double>(prog_.code.size() + 1));  // pops the value
      return end + 1;
    }
    if (!assign) {
      error(line, i, "expected '=' after '" + word + "' (statements are assignments, 'if', 'while' and 'do')");
      return -1;
    }
    const int end = scanner_.findTop(line, i + 1, e, ';');
    if (end < 0) {
      error(line, at, "missing ';' after the assignment to '" + word + "' (cpfg requires one after every statement)");
      return -1;
    }
    const Span value = scanner_.trim(Span{line, i + 1, end});
    if (value.b == value.e) {
      error(line, i, "missing value after '" + word + " ='");
      return -1;
    }
    if (!assignable(line, at, word, varNames)) return -1;
    const std::string_view text = scanner_.view(value);
    const bool fopen = prog_.dialect == Dialect::Cpfg && text.substr(0, 5) == "fopen" &&
                       nextNonSpace(line, value.b + 5, value.e) < value.e && s[nextNonSpace(line, value.b + 5, value.e)] == '(';
    if (fopen) {
      if (!fileCallAllowed(line, value.b, "fopen") || !fopenValue(value)) return -1;
    } else if (!expr_.compile(value, varNames, "value")) {
      return -1;
    }
    const auto slot = storeSlot(line, at, word, varNames);
    if (!slot) return -1;
    Instr store;
    store.op = Op::Store;
    store.var = *slot;
    prog_.code.push_back(store);
    return end + 1;
  }

  /// Whether `word` may be assigned here: not a #define, not an array, and not a global
  /// unless a cpfg production assigns it (an error names the case).
  bool assignable(int line, int at, const std::string& word, const std::vector<std::string>& varNames) {
    if (defines_.count(word)) {
      error(line, at, "cannot assign to '" + word + "': it is a #define");
      return false;
    }
    if (expr_.arrayId(word) >= 0) {
      error(line, at, "cannot assign to '" + word + "': it is an array (assign its elements, '" + word + "[i] = ...')");
      return false;
    }
    if (ruleGlobal(word, varNames) && (prog_.dialect != Dialect::Cpfg || statementBlock_ == Block::Interpretation)) {
      error(line, at, "cannot assign the global variable '" + word + "' in " +
                          (prog_.dialect != Dialect::Cpfg
                               ? std::string("a production of a .lsys file (Sprig assigns globals only in 'Start:', "
                                             "'StartEach:', 'EndEach:' and 'End:' blocks; a .l file's productions may)")
                               : std::string("an interpretation rule (cpfg would change it whenever it draws the "
                                             "string): not supported")));
      return false;
    }
    return true;
  }

  /// Whether an assignment to `word` in a rule assigns a global (no local of that name).
  bool ruleGlobal(const std::string& word, const std::vector<std::string>& varNames) const {
    return !inGlobalBlock_ && std::find(varNames.begin(), varNames.end(), word) == varNames.end() &&
           std::find(prog_.globals.begin(), prog_.globals.end(), word) != prog_.globals.end();
  }

  /// The variable slot an assignment to `word` stores into, once its value is compiled: a
  /// global a cpfg production assigns (it changes at once, for the modules rewritten after
  /// this one), a known local, or a new local; nullopt when there are too many.
  std::optional<uint16_t> storeSlot(int line, int at, const std::string& word, std::vector<std::string>& varNames) {
    if (ruleGlobal(word, varNames)) {
      prog_.rulesAssignGlobals = true;
      const auto global = std::find(prog_.globals.begin(), prog_.globals.end(), word);
      return static_cast<uint16_t>(kMaxVars - 1 - (global - prog_.globals.begin()));
    }
    auto it = std::find(varNames.begin(), varNames.end(), word);
    if (it == varNames.end()) {
      if (varNames.size() >= static_cast<size_t>(kMaxVars) - (inGlobalBlock_ ? 0 : prog_.globals.size())) {
        error(line, at, "too many parameters and local variables in one production (at most " + std::to_string(kMaxVars) + ")");
        return std::nullopt;
      }
      varNames.push_back(word);
      it = varNames.end() - 1;
    }
    return static_cast<uint16_t>(it - varNames.begin());
  }

  /// Open brackets of a module string being checked (bracketModule, bracketEnd).
  struct BracketState {
    std::vector<int> open;  ///< columns of the `[` not yet closed
    bool ok = true;
  };

  /// Reports m when it is a `]` closing nothing or a `[` beyond kMaxBracketDepth (in an
  /// axiom or successor, named by where).
  void bracketModule(int line, const RawModule& m, BracketState& st, const char* where) {
    if (m.name == "[") {
      st.open.push_back(m.col);
      if (st.open.size() == kMaxBracketDepth + 1) {
        error(line, m.col, std::string("branches in ") + where + " are nested more than " + std::to_string(kMaxBracketDepth) +
                               " levels deep (the limit)");
        st.ok = false;
      }
    } else if (m.name == "]") {
      if (st.open.empty()) {
        error(line, m.col, std::string("unmatched ']' in ") + where);
        st.ok = false;
      } else {
        st.open.pop_back();
      }
    }
  }

  /// Reports every `[` left open; true when the whole string was balanced.
  bool bracketEnd(int line, BracketState& st, const char* where) {
    for (int col : st.open) {
      error(line, col, std::string("unclosed '[' in ") + where + " (no matching ']')");
      st.ok = false;
    }
    return st.ok;
  }

  /// Reports brackets that do not pair up in mods (an axiom or a successor, named by where).
  bool checkBrackets(int line, const std::vector<RawModule>& mods, const char* where) {
    BracketState st;
    for (const RawModule& m : mods) bracketModule(line, m, st, where);
    return bracketEnd(line, st, where);
  }

  /// A note where the override of `derivation length:` was written (a species' `steps:`),
  /// when the file writes a different length: the override is silent otherwise.
  void noteLengthOverride() {
    const SourceLoc& at = overrides_.derivationLengthLoc;
    const int value = *overrides_.derivationLength;
    if (at.file.empty() || prog_.lengthLoc.line <= 0 || value == prog_.derivationLength) return;
    Diagnostic d;
    d.severity = Severity::Note;
    d.loc = at;
    d.message = std::to_string(value) + " steps replace the grammar's 'derivation length: " +
                std::to_string(prog_.derivationLength) + "' (" + prog_.lengthLoc.file + ":" +
                std::to_string(prog_.lengthLoc.line) + ")";
    diags().add(std::move(d));
  }

  /// A run of one-letter modules written with nothing between them (see lintWord).
  struct WordLint {
    int begin = -1;     ///< column of the run's first letter, -1 when no run is open
    int next = -1;      ///< column where the run's next letter must stand
    std::string word;   ///< the letters so far
  };

  /// Sprig's notation reads `Leaf(1)` without `module Leaf` as four modules `L e a f(1)`.
  /// A run of one-letter modules that spells a capitalized word of three letters or more
  /// (`Leaf`, `Apex`, `Bud`), written with nothing between its letters, is almost surely such
  /// a name: warn, naming the declaration to add. m == nullptr ends the line.
  void lintWord(int line, WordLint& w, const RawModule* m) {
    if (prog_.dialect != Dialect::Sprig) return;
    const bool letter = m && m->name.size() == 1 && std::isalpha(static_cast<unsigned char>(m->name[0]));
    const bool joins = letter && m->col == w.next && !w.word.empty() &&
                       std::islower(static_cast<unsigned char>(m->name[0]));
    if (joins) {
      w.word += m->name;
    } else {
      if (w.word.size() >= 3 && !lintedWords_.count(w.word)) {
        lintedWords_.insert(w.word);  // once per word
        auto [loc, text] = scanner_.locate(line, w.begin);
        diags().warning(loc,
                        "'" + w.word + "' is read as " + std::to_string(w.word.size()) +
                            " one-letter modules; declare it with 'module " + w.word + "' to make it one module",
                        std::move(text));
      }
      w.word.clear();
      if (letter && std::isupper(static_cast<unsigned char>(m->name[0]))) {
        w.word = m->name;
        w.begin = m->col;
      }
    }
    if (m) w.next = m->hasParens || !letter ? -1 : m->col + 1;
  }

  /// lintWord over one module string.
  void lintWords(int line, const std::vector<RawModule>& mods) {
    WordLint w;
    for (const RawModule& m : mods) lintWord(line, w, &m);
    lintWord(line, w, nullptr);
  }

  /// Records the parameter count of every module written in an axiom or successor.
  void noteWritten(int line, const std::vector<RawModule>& mods) {
    for (const RawModule& m : mods) noteWritten(line, m);
  }

  /// Records m's parameter count, with its first place. One-character names with fewer
  /// than 8 parameters are remembered in a bit table, so a long axiom costs no map lookup
  /// per module.
  void noteWritten(int line, const RawModule& m) {
    const size_t n = m.args.size();
    if (n == 0 && m.name.size() == 1 && std::string_view("+-&^\\/").find(m.name[0]) != std::string_view::npos) prog_.bareTurn = true;
    uint8_t* seen = m.name.size() == 1 && n < 8 ? &writtenSingle_[static_cast<unsigned char>(m.name[0])] : nullptr;
    if (seen && (*seen >> n & 1)) return;
    written_[m.name].emplace(static_cast<int>(n), std::pair{line, m.col});
    if (seen) *seen |= uint8_t(1u << n);
    if (m.name == "?" && n >= 1) subCalls_.push_back({line, m.col, std::string(scanner_.view(scanner_.trim(m.args[0])))});
  }

  /// cpfg's `?(n, s)` calls and `$`: a call whose n is a number naming no L-system of the
  /// file, and a `$` in a file without any call (ABOP's roll to vertical, which is `@v` in
  /// cpfg), are errors at their positions.
  void checkSubLsystemCalls() {
    if (prog_.dialect != Dialect::Cpfg) return;
    if (subCalls_.empty()) {
      if (auto it = written_.find("$"); it != written_.end()) {
        const auto [line, col] = it->second.begin()->second;
        error(line, col, "cpfg's '$' ends a sub-L-system call '?(n, scale)', and this file makes none (ABOP's roll to "
                         "vertical is '@v' in cpfg)");
      }
      return;
    }
    for (const SubCall& c : subCalls_) {
      double id = 0;
      auto r = std::from_chars(c.first.data(), c.first.data() + c.first.size(), id);
      if (r.ec != std::errc() || r.ptr != c.first.data() + c.first.size()) continue;  // an expression: checked when derived
      bool known = prog_.mainLsystemId && *prog_.mainLsystemId == id;
      for (const SubLsystem& sub : prog_.subLsystems) known |= sub.id == id;
      if (!known)
        error(c.line, c.col, "'?(" + c.first + ", ...)' calls a sub-L-system the file does not define (no 'lsystem: " + c.first +
                                 "' after an 'endlsystem')");
    }
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
                (one ? " parameter" : " parameters") + " (as at " + scanner_.lineRef(first.first, first.second) +
                "), so this production never applies");
    }
  }

  /// A user module (not a turtle command, whose parameters are optional) written in the
  /// axiom or a successor with a parameter count none of its productions takes, while
  /// productions for other counts exist: cpfg and lpfg match a module only with the same
  /// count, so the module would silently never be rewritten. Reported at the written
  /// module, naming the production. Symbols already reported by checkArities (a
  /// production whose count is never written) are left to that message.
  void checkWrittenArities() {
    std::map<std::string, std::map<int, const ArityUse*>> predecessors;
    for (const ArityUse& u : arityUses_)
      if (!u.context) predecessors[u.name].emplace(u.arity, &u);
    for (const auto& [name, counts] : predecessors) {
      auto w = written_.find(name);
      // (cpfg's `_`, its old elasticity, is a turtle command too: `_(e)` or `_` alone.)
      // (cpfg's `?E` too: vlab's clover writes `?E(1)` beside a production for `?E(t,la)`,
      // which cpfg accepts and never applies to it.)
      if (w == written_.end() || isTurtleSymbol(name) || (prog_.dialect == Dialect::Cpfg && (name == "_" || name == "?E")))
        continue;
      bool reported = std::any_of(counts.begin(), counts.end(), [&](const auto& c) { return !w->second.count(c.first); });
      if (reported) continue;
      const ArityUse& prod = *counts.begin()->second;
      for (const auto& [count, where] : w->second) {
        if (counts.count(count)) continue;
        auto plural = [](int n) { return std::to_string(n) + (n == 1 ? " parameter" : " parameters"); };
        const std::string msg = "module '" + name + "' is written here with " + plural(count) + ", but its production '" +
                                prod.text + "' (line " + std::to_string(prod.line) + ":" + std::to_string(prod.col + 1) +
                                ") takes " + plural(prod.arity) +
                                ": a production matches a module only with its own parameter count, so this module is never rewritten";
        if (prog_.dialect != Dialect::Cpfg) {
          error(where.first, where.second, msg);
          continue;
        }
        // cpfg derives such a file (vlab's two-trees writes 'L' beside 'L(del,vig)'), never
        // rewriting the module, and so does Sprig: a warning.
        auto [loc, text] = scanner_.locate(where.first, where.second);
        diags().warning(loc, msg + ", as in cpfg", std::move(text));
      }
    }
  }

  /// True for the built-in turtle symbols and named surfaces (`~l`), whose parameters are optional.
  static bool isTurtleSymbol(const std::string& name) {
    if (name.size() > 1 && name[0] == '~') return true;
    return std::any_of(std::begin(kTurtleSymbols), std::end(kTurtleSymbols), [&](const char* t) { return name == t; });
  }

  /// A predecessor whose stochastic productions all have weight 0 could never be rewritten
  /// by them (the derivation would silently keep the module): an error at the first.
  void checkWeights(const RuleSet& rs) {
    std::map<SymbolId, std::vector<const Production*>> bySymbol;
    for (const Production& p : rs.productions)
      if (p.stochastic) bySymbol[p.predecessor].push_back(&p);
    for (const auto& [sym, ps] : bySymbol) {
      if (std::any_of(ps.begin(), ps.end(), [](const Production* p) { return p->weight > 0; })) continue;
      std::string lines;
      for (size_t k = 0; k < ps.size(); ++k) lines += (k ? ", " : "") + std::to_string(ps[k]->loc.line);
      error(ps[0]->loc.line, ps[0]->loc.col - 1,
            "every stochastic production of '" + prog_.symbols.name(sym) + "' has weight 0 (line" +
                (ps.size() > 1 ? "s " : " ") + lines + "): at least one weight must be positive");
    }
  }

  static const char* blockName(Block b) {
    return b == Block::Decomposition ? "decomposition" : b == Block::Interpretation ? "interpretation" : "main";
  }

  /// Registers m's formal parameter names; returns their count.
  int formals(const RawModule& m, std::vector<std::string>& varNames) {
    for (const Span& a0 : m.args) {
      Span a = scanner_.trim(a0);
      std::string name(scanner_.view(a));
      bool valid = !name.empty() && isIdentStart(name[0]) && std::all_of(name.begin(), name.end(), [](char c) { return isIdentChar(c); });
      if (!valid) {
        error(a.line, a.b, "expected a parameter name, got '" + name + "'");
      } else if (std::find(varNames.begin(), varNames.end(), name) != varNames.end()) {
        error(a.line, a.b, "parameter '" + name + "' is already used in this production");
      } else if (defines_.count(name)) {
        error(a.line, a.b, "parameter '" + name + "' has the name of a #define");
      } else if (varNames.size() + prog_.globals.size() >= static_cast<size_t>(detail::kMaxVars)) {
        error(a.line, a.b, "too many parameters in one production (at most " + std::to_string(detail::kMaxVars) +
                               " with the global variables)");
      }
      varNames.push_back(name);
    }
    return static_cast<int>(m.args.size());
  }

  /// The context pattern sp (left or right of the predecessor), registering its formal parameters.
  std::vector<PatternItem> pattern(Span sp, std::vector<std::string>& varNames, bool left) {
    std::vector<RawModule> mods;
    std::vector<PatternItem> items;
    if (!scanner_.tokenizeModules(sp.line, sp.b, sp.e, mods)) return items;
    for (const RawModule& m : mods) {
      PatternItem it;
      if (m.name == "[" || m.name == "]") {
        if (left) {
          error(sp.line, m.col, "brackets are not allowed in a left context");
          continue;
        }
        it.openBracket = m.name == "[";
        it.closeBracket = m.name == "]";
      } else if (m.name == "=" && !left && prog_.dialect == Dialect::Cpfg) {
        // cpfg's `=`: skip the rest of the current branch (RconDiff in generate.c)
        if (m.hasParens) error(sp.line, m.col, "cpfg's '=' in a right context (skip the rest of the branch) takes no parameters");
        it.skipBranch = true;
      } else {
        it.symbol = prog_.symbols.intern(m.name);
        it.firstVar = static_cast<uint16_t>(varNames.size());
        it.paramCount = static_cast<uint16_t>(formals(m, varNames));
        arityUses_.push_back({m.name, it.paramCount, sp.line, m.col, scanner_.moduleText(sp.line, m), true});
      }
      items.push_back(it);
    }
    return items;
  }

  /// Appends modules whose parameters are constant expressions (random draws use rng).
  void appendConstant(const std::vector<RawModule>& mods, ModuleString& out, Rng* rng) {
    for (const RawModule& m : mods) appendConstant(m, out, rng);
  }

  /// Appends m, its parameters evaluated (nothing when one fails, after its diagnostic).
  void appendConstant(const RawModule& m, ModuleString& out, Rng* rng) {
    SymbolId id = prog_.symbols.intern(m.name);
    params_.clear();
    bool ok = true;
    for (const Span& a : m.args) {
      CodeRange later;
      const bool deferrable = &out == &prog_.axiom && prog_.dialect == Dialect::Cpfg;
      std::optional<double> v = expr_.evaluate(scanner_.trim(a), rng, deferrable ? &later : nullptr);
      if (!later.empty())
        prog_.axiomDeferred.emplace_back(static_cast<uint32_t>(out.params.size() + params_.size()), later);
      if (v && prog_.floatParams) v = static_cast<double>(static_cast<float>(*v));  // cpfg's floats
      if (v) params_.push_back(*v);
      else ok = false;
    }
    if (ok) out.push(id, params_);
  }

  // ---- end of file -------------------------------------------------------------------

  /// Overrides, the axiom, the ignore table and the lookup tables (see the class comment).
  void finish() {
    if (overrides_.derivationLength) {
      noteLengthOverride();
      prog_.lengthLoc = SourceLoc{};  // the length no longer comes from the file
      prog_.lengthLine.clear();
      if (*overrides_.derivationLength < 0) diags().error(SourceLoc{prog_.fileName, 0, 0}, "derivation length override must not be negative");
      prog_.derivationLength = *overrides_.derivationLength;
    }
    if (overrides_.seed) {
      prog_.seed = *overrides_.seed;
      prog_.seedOverridden = true;
    }
    if (prog_.name.empty()) prog_.name = std::filesystem::path(prog_.fileName).stem().string();
    if (axiomLine_ == 0 && !seen_.count("axiom")) {
      diags().error(SourceLoc{prog_.fileName, 0, 0}, "missing 'axiom:'");
    } else if (axiomLine_) {
      Rng rng(deriveSeed(prog_.seed, {kAxiomStream}));
      scanner_.tokenizeModules(axiomLine_, axiomSpan_.b, axiomSpan_.e,
                               [&](const RawModule& m) { appendConstant(m, prog_.axiom, &rng); });
    }
    if (prog_.ring && !prog_.subLsystems.empty())
      diags().error(SourceLoc{prog_.fileName, 0, 0},
                    "cpfg's 'ring lsystem' in a file with sub-L-systems is not supported (Sprig joins the ends of the "
                    "main L-system's string only)");
    // Ignore / consider table over every symbol, including ones interned late.
    prog_.ignored.assign(prog_.symbols.size(), 0);
    if (!considerList_.empty()) {
      std::fill(prog_.ignored.begin(), prog_.ignored.end(), 1);
      for (SymbolId id : considerList_) prog_.ignored[id] = 0;
    }
    for (SymbolId id : ignoreList_) prog_.ignored[id] = 1;
    // cpfg skips the brackets its ignore table holds (`ignore: [`, or `consider:` without
    // them) as any ignored symbol in a right context (generate.c, RconDiff); a left context
    // follows them whatever the table says (LconDiff). Sprig's notation always follows them.
    const bool bracketsIgnorable = prog_.dialect == Dialect::Cpfg;
    if (!bracketsIgnorable) prog_.ignored[prog_.openBracket] = prog_.ignored[prog_.closeBracket] = 0;
    // Each sub-L-system's own table (cpfg: LSYSDATA::ignore), used inside its calls.
    for (size_t k = 0; k < prog_.subLsystems.size() && k < subs_.size(); ++k) {
      std::vector<uint8_t>& ignored = prog_.subLsystems[k].ignored;
      ignored.assign(prog_.symbols.size(), subs_[k].considerList.empty() ? 0 : 1);
      for (SymbolId id : subs_[k].considerList) ignored[id] = 0;
      for (SymbolId id : subs_[k].ignoreList) ignored[id] = 1;
      if (!bracketsIgnorable) ignored[prog_.openBracket] = ignored[prog_.closeBracket] = 0;
    }
    for (SymbolId id : prog_.axiom.symbols) prog_.usesCut |= id == prog_.cut;
    for (const char* q : {"?P", "?H", "?L", "?U"}) prog_.usesQuery |= prog_.symbols.find(q) >= 0;
    prog_.usesEnvQuery = prog_.symbols.find("?E") >= 0;
    std::vector<RuleSet*> sets{&prog_.productions, &prog_.decomposition, &prog_.interpretation};
    std::vector<const RuleSet*> interpretations{&prog_.interpretation};
    for (SubLsystem& sub : prog_.subLsystems) {
      sets.insert(sets.end(), {&sub.productions, &sub.decomposition, &sub.interpretation});
      interpretations.push_back(&sub.interpretation);
    }
    for (const RuleSet* rs : sets)
      if (std::find(interpretations.begin(), interpretations.end(), rs) == interpretations.end())
        for (const Production& p : rs->productions)
          for (const SuccModule& m : p.successor) prog_.usesCut |= m.symbol == prog_.cut;
    if (int q = prog_.symbols.find("?"); q >= 0) prog_.subCall = static_cast<SymbolId>(q);
    prog_.subEnd = static_cast<SymbolId>(prog_.symbols.find("$"));
    if (prog_.dialect == Dialect::Cpfg) {
      for (RuleSet* rs : sets)
        if (std::find(interpretations.begin(), interpretations.end(), rs) != interpretations.end()) expandGenCylRules(*rs, sets);
      checkSplitCommands(sets);
    }
    for (RuleSet* rs : sets) {
      rs->bySymbol.assign(prog_.symbols.size(), {});
      for (uint32_t i = 0; i < rs->productions.size(); ++i) {
        rs->bySymbol[rs->productions[i].predecessor].push_back(i);
        rs->anyContext |= rs->productions[i].hasContext();
      }
      rs->finalize();
    }
  }

  /// cpfg's interpretation rule `@G --> succ` (vlab's two-trees writes `@G --> *` to draw
  /// its stems without generalized cylinders): cpfg's string keeps one character per module,
  /// so the rule matches the '@' and 'G' of every `@Gs`, `@Gc(n)`, `@Ge(n)`, `@Gt(a,b)`,
  /// `@Gr(...)` and replaces them, leaving the command's last letter with its parameters,
  /// which cpfg's turtle does not draw (interpret.c has no case for c, e, t or r, and 's'
  /// only for an environment with 2 or 3 parameters). Sprig reads each command as one module:
  /// the rule becomes one rule per command and parameter count the grammar writes, in its
  /// place, which replaces the whole command (a rule for the left-over letter is the error of
  /// checkSplitCommands).
  void expandGenCylRules(RuleSet& rs, const std::vector<RuleSet*>& sets) {
    const int prefix = prog_.symbols.find(kGenCylPrefix);
    if (prefix < 0) return;
    std::vector<std::pair<SymbolId, uint16_t>> written;  // (command, parameter count)
    auto wrote = [&](SymbolId id, size_t n) {
      const std::string& name = prog_.symbols.name(id);
      if (name.size() != 3 || name.compare(0, 2, kGenCylPrefix) != 0) return;
      const std::pair<SymbolId, uint16_t> w{id, static_cast<uint16_t>(n)};
      if (std::find(written.begin(), written.end(), w) == written.end()) written.push_back(w);
    };
    for (size_t i = 0; i < prog_.axiom.size(); ++i) wrote(prog_.axiom.symbols[i], prog_.axiom.paramCount(i));
    for (const RuleSet* other : sets)
      for (const Production& p : other->productions)
        for (const SuccModule& m : p.successor) wrote(m.symbol, m.argCount);
    std::sort(written.begin(), written.end());
    std::vector<Production> out;
    for (Production& p : rs.productions) {
      if (p.predecessor != static_cast<SymbolId>(prefix)) {
        out.push_back(std::move(p));
        continue;
      }
      for (const auto& [id, n] : written) {
        Production c = p;
        c.predecessor = id;
        c.predParams = n;
        // The command's parameters go to registers the rule does not read.
        c.predFirstVar = static_cast<uint16_t>(p.localFirst + p.localCount);
        if (c.predFirstVar + n + prog_.globals.size() > kMaxVars) {
          diags().error(p.loc, "too many variables in cpfg's '@G' rule", p.sourceLine);
          return;
        }
        out.push_back(std::move(c));
      }
    }
    rs.productions = std::move(out);
  }

  /// cpfg keeps one character per module: its commands `@o(d)`, `?P(x,y,z)`, `~l` are the
  /// module `@` (`?`, `~`) followed by the modules of the letters after it, and a rule whose
  /// predecessor or context is one of those letters rewrites or reads them there. Sprig
  /// reads such a command as one module, so a rule naming a letter of a command the
  /// grammar writes is an error (else it would silently not apply where cpfg's does).
  void checkSplitCommands(const std::vector<RuleSet*>& sets) {
    // Per symbol: bit n set when the axiom or a successor writes it with n parameters.
    std::vector<uint64_t> counts(prog_.symbols.size(), 0);
    auto wrote = [&](SymbolId id, size_t n) { counts[id] |= uint64_t(1) << std::min<size_t>(n, 63); };
    for (size_t i = 0; i < prog_.axiom.size(); ++i) wrote(prog_.axiom.symbols[i], prog_.axiom.paramCount(i));
    for (const RuleSet* rs : sets)
      for (const Production& p : rs->productions)
        for (const SuccModule& m : p.successor) wrote(m.symbol, m.argCount);
    // The written command a rule's module (letter, n parameters) would match in cpfg's string:
    // its last letter carries the command's parameters, the others none.
    // Every written command whose letter a rule's module (letter, n parameters) matches.
    auto commands = [&](SymbolId id, size_t n) {
      std::vector<std::pair<SymbolId, bool>> found;  // (command, the letter is its last)
      const std::string& letter = prog_.symbols.name(id);
      if (letter.size() != 1) return found;
      for (size_t c = 0; c < counts.size(); ++c) {
        const std::string& name = prog_.symbols.name(static_cast<SymbolId>(c));
        if (!counts[c] || name.size() < 2 || (name[0] != '@' && name[0] != '?' && name[0] != '~')) continue;
        for (size_t k = 1; k < name.size(); ++k)
          if (name[k] == letter[0] && (k + 1 == name.size() ? (counts[c] >> std::min<size_t>(n, 63)) & 1 : n == 0)) {
            found.emplace_back(static_cast<SymbolId>(c), k + 1 == name.size());
            break;
          }
      }
      return found;
    };
    std::vector<Production> clones;
    for (const RuleSet* rs : sets)
      for (const Production& p : rs->productions) {
        std::vector<std::pair<SymbolId, size_t>> mods{{p.predecessor, p.predParams}};
        for (const auto* side : {&p.predRest, &p.left, &p.right})
          for (const PatternItem& it : *side)
            if (!it.openBracket && !it.closeBracket && !it.skipBranch) mods.emplace_back(it.symbol, it.paramCount);
        for (size_t m = 0; m < mods.size(); ++m) {
          const auto [id, n] = mods[m];
          const auto found = commands(id, n);
          if (found.empty()) continue;
          // A production (no left context, statements or predecessor of several modules)
          // whose successor starts with the letter again: cpfg rewrites the letter of the
          // command and keeps its '@', which reads as the command once more (vlab's Mycelis
          // grows '@o(r)' with 'o(r) --> o(r+0.03)'): the same production for the command.
          const bool cloneable = m == 0 && rs == &prog_.productions && p.left.empty() && p.predRest.empty() &&
                                 !p.hasStatements() && !p.successor.empty() && p.successor[0].symbol == id &&
                                 std::all_of(found.begin(), found.end(), [](const auto& f) { return f.second; });
          if (cloneable) {
            for (const auto& f : found) {
              clones.push_back(p);
              clones.back().predecessor = clones.back().successor[0].symbol = f.first;
            }
            continue;
          }
          {
            const std::optional<std::string> cmd = prog_.symbols.name(found.front().first);
            const std::string& letter = prog_.symbols.name(id);
            std::string parts;
            for (char c : *cmd) parts += (parts.empty() ? "'" : ", '") + std::string(1, c) + "'";
            diags().error(p.loc,
                          "cpfg reads '" + *cmd + "' as the modules " + parts + " (one character each), so this rule's '" +
                              letter + "' also matches the '" + letter + "' of the '" + *cmd +
                              "' the grammar writes; Sprig reads '" + *cmd + "' as one module: not supported (rename the module '" +
                              letter + "')",
                          p.sourceLine);
            break;
          }
        }
      }
    for (Production& c : clones) {
      prog_.splitCommand.resize(prog_.symbols.size(), 0);
      prog_.splitCommand[c.predecessor] = 1;
      prog_.productions.productions.push_back(std::move(c));
    }
  }

  GrammarOverrides overrides_;
  Program prog_;
  Scanner scanner_;
  std::unordered_map<std::string, double> defines_;
  ExpressionParser expr_{scanner_, defines_, prog_.code};
  std::map<std::string, int> seen_;
  Span axiomSpan_;  ///< the axiom's text (tokenized again by finish())
  int axiomLine_ = 0;
  std::vector<double> params_;  ///< scratch parameters of appendConstant
  std::array<uint8_t, 256> writtenSingle_{};  ///< per byte: bit n set when written with n parameters
  std::vector<SymbolId> ignoreList_, considerList_;
  /// cpfg's sub-L-system calls `?(n, ...)` written in the axiom and successors: line,
  /// column and the text of n.
  struct SubCall {
    int line = 0, col = 0;
    std::string first;
  };
  std::vector<SubCall> subCalls_;
  bool afterEnd_ = false;         ///< an `endlsystem` was read and no `lsystem:` since
  /// The labels of the sub-L-systems read so far (the last is being read), with the
  /// scanner line and column of their `lsystem:` headers.
  struct SubHeader {
    std::string label;
    int line = 0, col = 0;
    std::vector<SymbolId> ignoreList, considerList;  ///< its `ignore:` or `consider:`
  };
  std::vector<SubHeader> subs_;
  bool inGlobalBlock_ = false;  ///< compiling a Start/End block: its variables are the globals
  Block statementBlock_ = Block::Main;  ///< the block of the production whose statements are compiled
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
  std::set<std::string> lintedWords_;  ///< words lintWord has warned about
};

}  // namespace

std::shared_ptr<Program> compileGrammar(std::string_view text, const std::string& fileName, const GrammarOverrides& overrides) {
  return GrammarParser(fileName, overrides).run(text);
}

ModuleString compileModuleString(std::string_view text, SymbolTable& symbols, const std::string& fileName) {
  return GrammarParser(fileName, {}).constantString(text, symbols);
}

}  // namespace sprig::lsystem::detail
