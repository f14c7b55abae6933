#pragma once
/// The grammar file's scanner: its lines with comments blanked out, spans of them, the
/// diagnostics every parser of the grammar language reports through, and the tokenizer
/// that splits a module string (`F(1)[+A(x,2)]`) into modules with argument spans.
/// Private to lsystem/; used by the expression parser and the grammar parser.

#include <cctype>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/diagnostics.h"
#include "lsystem/detail/cpfg.h"

namespace sprig::lsystem::detail {

inline bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }
inline bool isIdentStart(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
inline bool isIdentChar(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

/// s cut at every `\n`, each line without a trailing `\r`.
std::vector<std::string> splitAtNewlines(const std::string& s);
/// text with `//` and block comments replaced by spaces (newlines kept, so columns stay);
/// pending gets the (line, 0-based column) of a block comment never closed ({0, 0}: none).
std::string blankComments(std::string_view text, std::pair<int, int>& pending);

/// v in its shortest round-trip form (`0.5`, `1e+300`, `inf`), as diagnostics print numbers.
std::string formatNumber(double v);

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

/// A `key:` header at the start of a line.
struct Header {
  std::string key;  ///< lower-cased, single-spaced
  int valueBegin = 0;
};

/*
 * Scanner: the text of one grammar file held as two parallel arrays of lines, as written
 * (`raw`, quoted under each diagnostic) and cleaned (`//` and block comments replaced by
 * spaces, so a column in a cleaned line is the column in the file). Everything after
 * load() works on cleaned lines through Spans, without copying text.
 *
 * Every diagnostic of the grammar language goes through error(), which adds
 * `file:line:col` and the raw line; they are collected here and thrown once by the caller.
 * The scanner also owns the multi-character module names (`Apex`, `@Ts`) the tokenizer
 * matches longest first; any other character is a module of its own.
 */
class Scanner {
 public:
  /// fileName names the text in every diagnostic.
  explicit Scanner(std::string fileName) : fileName_(std::move(fileName)) {}

  /// Splits text into raw and cleaned lines (a trailing `\r` is dropped) and blanks out
  /// comments. An unclosed block comment is remembered (see unterminatedComment()).
  void load(std::string_view text);

  /// Number of lines of the loaded text.
  int lineCount() const { return static_cast<int>(clean_.size()); }
  /// Cleaned line `line` (1-based).
  const std::string& line(int line) const { return clean_[line - 1]; }
  /// Line `line` (1-based) as written.
  const std::string& rawLine(int line) const { return raw_[line - 1]; }
  const std::string& fileName() const { return fileName_; }
  /// Where column col0 of logical line `line` was written: its file (the grammar's, or a
  /// file it includes), 1-based line and column, and that line's text as written.
  std::pair<SourceLoc, std::string> locate(int line, int col0) const;
  /// "line N" (or "line N:C" with a column) for a logical line of the grammar file itself,
  /// "FILE:N" ("FILE:N:C") for one of an included file: how messages name another place.
  std::string lineRef(int line, int col0 = -1) const;
  /// (line, 0-based column) of a block comment that is never closed; line 0 when none.
  std::pair<int, int> unterminatedComment() const { return pendingComment_; }

  /// The diagnostics reported so far.
  DiagnosticList& diagnostics() { return diags_; }
  const DiagnosticList& diagnostics() const { return diags_; }
  /// Reports an error at line (1-based), col0 (0-based), quoting the raw line. A column in
  /// a continued line's continuation is reported at its own line.
  void error(int line, int col0, std::string msg);
  /// The physical (line, 0-based column) of column col0 of logical line `line`.
  std::pair<int, int> physical(int line, int col0) const;

  /// sp without leading and trailing white space.
  Span trim(Span sp) const;
  /// The text of sp.
  std::string_view view(Span sp) const { return std::string_view(clean_[sp.line - 1]).substr(sp.b, sp.e - sp.b); }
  /// True when sp holds just `*` (the empty context, condition or successor).
  bool isStar(Span sp) const { return view(trim(sp)) == "*"; }

  /// Adds a multi-character module name for tokenizeModules (no-op when already known).
  void addMultiName(std::string_view name);
  /// Forgets every multi-character module name.
  void clearMultiNames() { multiNames_.clear(); }
  /// The notation modules are read in: the tokenizer reports cpfg commands Sprig does not
  /// implement in it (lsystem/detail/cpfg.h) as errors at their position.
  void setDialect(Dialect d) { dialect_ = d; }
  Dialect dialect() const { return dialect_; }
  /// cpfg: the ids of the view file's surfaces; `~X` with another X is an error.
  void setCpfgSurfaceIds(std::string ids, std::string undrawn = {}) {
    cpfgSurfaceIds_ = std::move(ids);
    cpfgUndrawnSurfaceIds_ = std::move(undrawn);
  }
  /// cpfg: names the preprocessor defines before the file, the k-th (0-based) as k + 1
  /// (the functions of a view file's `function set:`).
  void setPredefined(std::vector<std::string> names) { predefined_ = std::move(names); }
  /// Splits line(line)[b, e) into modules, appending them to out. Reports errors; returns
  /// false on an error that stops the line (a stray `(`, `)` or `,`, a missing `)`) or
  /// after reporting empty parameters.
  bool tokenizeModules(int line, int b, int e, std::vector<RawModule>& out);
  /// As above, handing each module to each instead of storing it (one RawModule is
  /// reused: no allocation per module). Used for the axiom, which may hold millions.
  bool tokenizeModules(int line, int b, int e, const std::function<void(const RawModule&)>& each);
  /// The module m of line `line` as written (its name and parameter list).
  std::string moduleText(int line, const RawModule& m) const;

  /// `key:` at s[b...] (letters and spaces before a colon), if any.
  static std::optional<Header> headerOf(const std::string& s, int b);
  /// Offset of the first non-space character of s (s.size() when none).
  static int firstNonSpace(const std::string& s);
  /// Position of the production arrow `-->` (or `->`) at parenthesis depth 0, with its
  /// length; {-1, 0} when there is none.
  static std::pair<int, int> findArrow(const std::string& s);
  /// Index of the first c at parenthesis depth 0 in line(line)[b, e), or -1.
  int findTop(int line, int b, int e, char c) const;
  /// Index of the last c at parenthesis depth 0 in line(line)[b, e), or -1.
  int findTopLast(int line, int b, int e, char c) const;

 private:
  /// cpfg's C preprocessor (docs/GRAMMAR.md, "The C preprocessor"), run on the lines of
  /// one file (raw and with comments blanked) before continuations are joined: appends the
  /// resulting lines, their origins and column maps to raw_, clean_, origin_, colMap_.
  void preprocess(int file, const std::vector<std::string>& raw, const std::vector<std::string>& clean, int depth);
  struct Directive;
  /// Appends one preprocessed line (file's 0-based line k, as written: raw) to raw_, clean_,
  /// origin_ and colMap_.
  void emitLine(int file, size_t k, const std::string& raw, std::string text, std::vector<int> map);
  void directiveError(const Directive& d, size_t col, const std::string& msg);
  /// Not inside a false `#ifdef` block.
  bool preprocessorActive() const;
  /// A `#`-line: `#ifdef`, `#ifndef`, `#if`, `#else`, `#endif`, `#define`, `#undef`,
  /// `#include`, or one the grammar parser reports.
  void directive(const Directive& d);
  /// `#ifdef`, `#ifndef`, `#if`, `#else`, `#endif`: true when d is one of them.
  bool conditionalDirective(const Directive& d);
  /// The value of an `#if` condition (nullopt: not a constant expression).
  std::optional<double> ifCondition(const std::string& text);
  void defineDirective(const Directive& d);
  void includeDirective(const Directive& d);
  struct Macro;
  /// line with the macros expanded; map gets the original column of each column.
  std::string expand(const std::string& line, std::vector<int>& map, int file, int lineNo, const std::string& rawLine);
  std::string expandText(const std::string& text, std::vector<std::string>& disabled, int depth, bool& failed);

  std::string fileName_;
  std::vector<std::string> raw_, clean_;
  /// Per physical line: the file (index into files_) and 1-based line it was written at,
  /// and the original column of each column when macros changed it (empty: the same).
  struct Origin {
    int file, line;
  };
  std::vector<std::string> files_;
  std::vector<Origin> origin_;
  std::vector<std::vector<int>> colMap_;
  /// The preprocessor's state: textual and function-like macros, constant `#define`s (left
  /// to the grammar parser), and open `#ifdef` blocks.
  struct Macro {
    std::vector<std::string> params;
    bool functionLike = false;
    std::string body;
    int file = 0, line = 0;
  };
  std::vector<std::pair<std::string, Macro>> macros_;
  std::vector<std::pair<std::string, int>> constants_;
  /// The body of each constant (`#define LEAVES 1`), for `#if`.
  std::vector<std::pair<std::string, std::string>> constantBodies_;
  struct Conditional {
    bool active, parentActive, elseSeen;
    int file, line, col;
  };
  std::vector<Conditional> conditionals_;
  /// A piece of a logical line that came from another line of the file (cpfg dialect:
  /// a line starting with a tab continues the one before it): from column `offset` of the
  /// logical line on, the text is line `line`'s from column `col` (all 0-based but line).
  struct Piece {
    int offset, line, col;
  };
  /// Per logical line with continuations: its pieces after the first (empty for most).
  std::vector<std::vector<Piece>> pieces_;
  std::vector<std::string> multiNames_;
  std::pair<int, int> pendingComment_{0, 0};
  Dialect dialect_ = Dialect::Sprig;
  std::string cpfgSurfaceIds_;
  std::string cpfgUndrawnSurfaceIds_;
  std::string warnedSurfaceIds_;  ///< undefined ids already warned about
  std::vector<std::string> predefined_;
  DiagnosticList diags_;
};

}  // namespace sprig::lsystem::detail
