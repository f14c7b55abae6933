#pragma once
/// Source locations, diagnostics and the InputError every parser throws.
///
/// A diagnostic prints as `path:line:col: error: message` (1-based line and column),
/// followed, when the source line is known, by that line and a caret under the column.
/// Parsers collect diagnostics in a DiagnosticList and throw once with all of them.

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace sprig {

/// A position in a user's file. line and col are 1-based; 0 means unknown.
struct SourceLoc {
  std::string file;
  int line = 0;
  int col = 0;
};

/// Most columns of a source line a diagnostic quotes: a longer line is shown as a window
/// of this many columns around the caret, cut ends marked "...".
inline constexpr size_t kDiagnosticWindow = 120;

/// Most diagnostics one DiagnosticList keeps (and so one InputError prints): the rest are
/// counted, and throwIfErrors ends with one note saying how many were not shown.
inline constexpr size_t kMaxDiagnostics = 50;

/// How serious a diagnostic is; only errors make DiagnosticList::throwIfErrors throw.
enum class Severity { Error, Warning, Note };

/// One message about a user's input.
struct Diagnostic {
  Severity severity = Severity::Error;
  SourceLoc loc;
  std::string message;
  std::string sourceLine;  ///< the text of loc.line, without its newline; may be empty
  /// Column (0-based) of the line at which sourceLine starts: lines far longer than the
  /// window are stored already cut (DiagnosticList keeps at most a few windows of them).
  size_t lineOffset = 0;
  bool lineCut = false;  ///< sourceLine ends before the line does

  /// `path:line:col: error: message`, plus the source line (at most kDiagnosticWindow
  /// columns of it around the caret) and a caret when known.
  std::string format() const;
};

/// A bad request from the command line found after parsing (a stage the species lacks, an
/// unknown output extension, a malformed -D). The `sprig` binary prints
/// `sprig: error: <what>` and exits with 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A whole string as a finite real number (`+`, exponents allowed), else nullopt.
std::optional<double> parseFiniteNumber(std::string_view text);

/// Bad user input (grammar, species file, texture, command-line value).
/// what() returns every diagnostic formatted, one after another.
class InputError : public std::runtime_error {
 public:
  /// An error holding diagnostics (what() formats them all, one per line group).
  explicit InputError(std::vector<Diagnostic> diagnostics);
  /// One error at loc.
  InputError(SourceLoc loc, std::string message, std::string sourceLine = {});

  /// Every diagnostic, in the order they were collected.
  const std::vector<Diagnostic>& diagnostics() const { return diagnostics_; }

 private:
  std::vector<Diagnostic> diagnostics_;
};

/// Collects diagnostics while a file is parsed; throwIfErrors() throws them all at once.
/// It keeps the first kMaxDiagnostics and counts the rest (a file of 100,000 bad lines
/// prints 51 messages, not 100,000).
class DiagnosticList {
 public:
  /// Adds an error at loc (sourceLine: the text of that line, for the caret).
  void error(SourceLoc loc, std::string message, std::string sourceLine = {});
  /// Adds a warning at loc; warnings never make throwIfErrors throw.
  void warning(SourceLoc loc, std::string message, std::string sourceLine = {});
  /// Adds d as it is.
  void add(Diagnostic d);
  /// Adds every diagnostic of ds, in order.
  void append(const std::vector<Diagnostic>& ds);

  /// True when any collected diagnostic is an error (a suppressed one too).
  bool hasErrors() const;
  /// The kept diagnostics, in order (at most kMaxDiagnostics).
  const std::vector<Diagnostic>& items() const { return items_; }
  /// How many diagnostics were counted but not kept.
  size_t suppressed() const { return suppressed_; }
  /// Throws InputError holding every kept diagnostic, then (when some were not kept) a note
  /// "N more diagnostics not shown (at most 50 are; kMaxDiagnostics)", when any is an error.
  void throwIfErrors() const;

 private:
  std::vector<Diagnostic> items_;
  size_t suppressed_ = 0;
  bool suppressedError_ = false;
  std::string suppressedFile_;  ///< the file of the first diagnostic not kept
};

/// The 1-based line `line` of text, without its line ending; empty if out of range.
std::string lineOf(std::string_view text, int line);

/// Edit distance between a and b: insertions, deletions, substitutions and transpositions
/// of two adjacent characters each count 1 (optimal string alignment, Damerau 1964).
int editDistance(std::string_view a, std::string_view b);

/// " (did you mean 'x'?)" for the closest candidate within a small edit distance, else "".
std::string didYouMean(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace sprig
