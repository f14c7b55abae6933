#include "core/diagnostics.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>

namespace sprig {

namespace {

const char* severityName(Severity s) {
  switch (s) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Note: return "note";
  }
  return "error";
}

/// The range [begin, end) of at most width characters of a line of size n around caret.
std::pair<size_t, size_t> windowAround(size_t n, size_t caret, size_t width) {
  if (n <= width) return {0, n};
  size_t begin = caret > width / 2 ? caret - width / 2 : 0;
  size_t end = std::min(n, begin + width);
  return {end - width, end};
}

/// A diagnostic whose source line, when far longer than the window, is stored cut to a few
/// windows around the caret (a 400,000-character line is never copied per diagnostic).
Diagnostic makeDiagnostic(Severity severity, SourceLoc loc, std::string message, std::string sourceLine) {
  Diagnostic d{severity, std::move(loc), std::move(message), {}};
  constexpr size_t kKeep = 4 * kDiagnosticWindow;
  if (sourceLine.size() > kKeep && d.loc.col > 0) {
    auto [begin, end] = windowAround(sourceLine.size(), static_cast<size_t>(d.loc.col - 1), kKeep);
    d.sourceLine = sourceLine.substr(begin, end - begin);
    d.lineOffset = begin;
    d.lineCut = end < sourceLine.size();
  } else {
    d.sourceLine = std::move(sourceLine);
  }
  return d;
}

std::string formatAll(const std::vector<Diagnostic>& ds) {
  std::string out;
  for (size_t i = 0; i < ds.size(); ++i) {
    if (i) out += '\n';
    out += ds[i].format();
  }
  return out;
}

}  // namespace

std::string Diagnostic::format() const {
  std::string out;
  if (!loc.file.empty()) {
    out += loc.file;
    if (loc.line > 0) {
      out += ':' + std::to_string(loc.line);
      if (loc.col > 0) out += ':' + std::to_string(loc.col);
    }
    out += ": ";
  }
  out += severityName(severity);
  out += ": ";
  out += message;
  if (!sourceLine.empty() && loc.col > 0) {
    // A long line is shown as a window of at most kDiagnosticWindow columns around the
    // caret, with "..." where it was cut, as compilers do.
    size_t col0 = static_cast<size_t>(loc.col - 1);
    size_t caret = std::min(col0 >= lineOffset ? col0 - lineOffset : 0, sourceLine.size());
    auto [begin, end] = windowAround(sourceLine.size(), caret, kDiagnosticWindow);
    const char* left = begin + lineOffset > 0 ? "..." : "";
    out += "\n  ";
    out += left;
    out.append(sourceLine, begin, end - begin);
    if (end < sourceLine.size() || lineCut) out += "...";
    out += "\n  ";
    out.append(std::string_view(left).size(), ' ');
    // Keep tabs so the caret lines up under tab-indented text.
    for (size_t i = begin; i < caret && i < end; ++i) out += sourceLine[i] == '\t' ? '\t' : ' ';
    out += '^';
  }
  return out;
}

InputError::InputError(std::vector<Diagnostic> diagnostics)
    : std::runtime_error(formatAll(diagnostics)), diagnostics_(std::move(diagnostics)) {}

InputError::InputError(SourceLoc loc, std::string message, std::string sourceLine)
    : InputError(std::vector<Diagnostic>{makeDiagnostic(Severity::Error, std::move(loc), std::move(message), std::move(sourceLine))}) {}

void DiagnosticList::error(SourceLoc loc, std::string message, std::string sourceLine) {
  if (items_.size() >= kMaxDiagnostics) return add(Diagnostic{Severity::Error, std::move(loc), {}, {}, 0, false});
  items_.push_back(makeDiagnostic(Severity::Error, std::move(loc), std::move(message), std::move(sourceLine)));
}

void DiagnosticList::warning(SourceLoc loc, std::string message, std::string sourceLine) {
  if (items_.size() >= kMaxDiagnostics) return add(Diagnostic{Severity::Warning, std::move(loc), {}, {}, 0, false});
  items_.push_back(makeDiagnostic(Severity::Warning, std::move(loc), std::move(message), std::move(sourceLine)));
}

void DiagnosticList::add(Diagnostic d) {
  if (items_.size() < kMaxDiagnostics) {
    items_.push_back(std::move(d));
    return;
  }
  if (suppressed_++ == 0) suppressedFile_ = d.loc.file;
  if (d.severity == Severity::Error) suppressedError_ = true;
}

void DiagnosticList::append(const std::vector<Diagnostic>& ds) {
  for (const Diagnostic& d : ds) add(d);
}

bool DiagnosticList::hasErrors() const {
  if (suppressedError_) return true;
  return std::any_of(items_.begin(), items_.end(), [](const Diagnostic& d) { return d.severity == Severity::Error; });
}

void DiagnosticList::throwIfErrors() const {
  if (!hasErrors()) return;
  if (suppressed_ == 0) throw InputError(items_);
  std::vector<Diagnostic> all = items_;
  all.push_back(makeDiagnostic(Severity::Note, SourceLoc{suppressedFile_},
                               std::to_string(suppressed_) + " more diagnostic" + (suppressed_ == 1 ? "" : "s") +
                                   " not shown (at most " + std::to_string(kMaxDiagnostics) + " are; kMaxDiagnostics)",
                               {}));
  throw InputError(std::move(all));
}

std::string lineOf(std::string_view text, int line) {
  if (line < 1) return {};
  size_t pos = 0;
  for (int l = 1; l < line; ++l) {
    pos = text.find('\n', pos);
    if (pos == std::string_view::npos) return {};
    ++pos;
  }
  size_t end = text.find('\n', pos);
  std::string_view s = text.substr(pos, end == std::string_view::npos ? std::string_view::npos : end - pos);
  if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
  return std::string(s);
}

int editDistance(std::string_view a, std::string_view b) {
  // Optimal string alignment: Levenshtein plus the transposition of two adjacent
  // characters as one edit ("steps" -> "setps" is 1). Three rolling rows: i-2, i-1, i.
  std::vector<int> prev2(b.size() + 1), prev(b.size() + 1), cur(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      int sub = prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, sub});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        cur[j] = std::min(cur[j], prev2[j - 2] + 1);
    }
    std::swap(prev2, prev);
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string didYouMean(std::string_view word, const std::vector<std::string>& candidates) {
  int best = std::numeric_limits<int>::max();
  const std::string* bestName = nullptr;
  for (const auto& c : candidates) {
    int d = editDistance(word, c);
    if (d < best) { best = d; bestName = &c; }
  }
  int limit = std::max<int>(2, static_cast<int>(word.size()) / 3);
  if (!bestName || best > limit) return {};
  return " (did you mean '" + *bestName + "'?)";
}

std::optional<double> parseFiniteNumber(std::string_view text) {
  if (!text.empty() && text[0] == '+') text.remove_prefix(1);
  double v = 0;
  auto res = std::from_chars(text.data(), text.data() + text.size(), v, std::chars_format::general);
  if (text.empty() || res.ec != std::errc() || res.ptr != text.data() + text.size() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

}  // namespace sprig
