#include "lsystem/detail/scanner.h"

#include <algorithm>
#include <charconv>
#include <tuple>

namespace sprig::lsystem::detail {

/// s cut at every `\n`, each line without a trailing `\r`.
std::vector<std::string> splitAtNewlines(const std::string& s) {
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
}

/// text with `//` and block comments replaced by spaces (newlines kept, so columns stay);
/// pending gets the (line, 0-based column) of a block comment never closed.
std::string blankComments(std::string_view text, std::pair<int, int>& pending) {
  std::string clean(text);
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
      if (!closed) pending = {startLine, startCol};
    } else {
      ++i;
    }
  }
  return clean;
}

std::string formatNumber(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

void Scanner::load(std::string_view text) {
  std::pair<int, int> pending{0, 0};
  const std::string clean = blankComments(text, pending);
  files_.assign(1, fileName_);
  raw_.clear();
  clean_.clear();
  origin_.clear();
  colMap_.clear();
  macros_.clear();
  constants_.clear();
  conditionals_.clear();
  // cpfg's function set names (`-DNAME=n` on its preprocessor's command line).
  for (size_t k = 0; k < predefined_.size(); ++k) {
    Macro m;
    m.body = std::to_string(k + 1);
    macros_.emplace_back(predefined_[k], m);
  }
  preprocess(0, splitAtNewlines(std::string(text)), splitAtNewlines(clean), 0);
  for (const Conditional& c : conditionals_)
    diags_.error(SourceLoc{files_[c.file], c.line, c.col + 1}, "'#if' block without '#endif'");
  pendingComment_ = {0, 0};
  if (pending.first)
    for (size_t k = 0; k < origin_.size(); ++k)
      if (origin_[k].file == 0 && origin_[k].line == pending.first) pendingComment_ = {static_cast<int>(k) + 1, pending.second};
  pieces_.assign(clean_.size(), {});
  if (dialect_ != Dialect::Cpfg) return;
  // cpfg's lexer reads a newline followed by a tab as white space: the line goes on. A
  // line that opens a `{` statement block after a `:` (and has no arrow yet) also goes on
  // until its braces close, so that the block is reported once, at its `{`.
  int open = 0;  // logical line being continued (0-based), -1 for none
  open = -1;
  for (size_t k = 0; k < clean_.size(); ++k) {
    const std::string& t = clean_[k];
    bool continues = open >= 0 && (!t.empty() && t[0] == '\t');
    if (open >= 0 && !continues) {
      const std::string& o = clean_[open];
      int depth = 0;
      for (char c : o) depth += c == '{' ? 1 : c == '}' ? -1 : 0;
      // Blank lines inside the braces go on too, as in cpfg's reader.
      continues = depth > 0 && o.find(':') != std::string::npos && findArrow(o).first < 0;
    }
    if (continues) {
      std::string& o = clean_[open];
      pieces_[open].push_back({static_cast<int>(o.size()) + 1, static_cast<int>(k) + 1, 0});
      o += ' ';
      o += t;
      clean_[k].clear();
    } else {
      open = static_cast<int>(k);
    }
  }
}

std::pair<int, int> Scanner::physical(int line, int col0) const {
  if (line < 1 || line > static_cast<int>(pieces_.size())) return {line, col0};
  std::pair<int, int> at{line, col0};
  for (const Piece& p : pieces_[line - 1])
    if (col0 >= p.offset) at = {p.line, p.col + col0 - p.offset};
  return at;
}

std::pair<SourceLoc, std::string> Scanner::locate(int line, int col0) const {
  std::tie(line, col0) = physical(line, col0);
  if (line < 1 || line > static_cast<int>(raw_.size())) return {SourceLoc{fileName_, line, col0 + 1}, ""};
  const Origin& o = origin_[line - 1];
  const std::vector<int>& m = colMap_[line - 1];
  int col = col0;
  if (!m.empty())
    col = col0 < static_cast<int>(m.size()) ? m[col0] : static_cast<int>(raw_[line - 1].size()) + col0 - static_cast<int>(m.size());
  return {SourceLoc{files_[o.file], o.line, col + 1}, raw_[line - 1]};
}

std::string Scanner::lineRef(int line, int col0) const {
  auto [loc, text] = locate(line, std::max(col0, 0));
  const bool own = line >= 1 && line <= static_cast<int>(origin_.size()) && origin_[line - 1].file == 0;
  std::string out = own ? "line " + std::to_string(loc.line) : loc.file + ":" + std::to_string(loc.line);
  if (col0 >= 0) out += ":" + std::to_string(loc.col);
  return out;
}

void Scanner::error(int line, int col0, std::string msg) {
  auto [loc, text] = locate(line, col0);
  diags_.error(loc, std::move(msg), std::move(text));
}

Span Scanner::trim(Span sp) const {
  const std::string& s = clean_[sp.line - 1];
  while (sp.b < sp.e && isSpace(s[sp.b])) ++sp.b;
  while (sp.e > sp.b && isSpace(s[sp.e - 1])) --sp.e;
  return sp;
}

void Scanner::addMultiName(std::string_view name) {
  if (std::find(multiNames_.begin(), multiNames_.end(), name) == multiNames_.end()) multiNames_.emplace_back(name);
}

bool Scanner::tokenizeModules(int line, int b, int e, std::vector<RawModule>& out) {
  return tokenizeModules(line, b, e, [&out](const RawModule& m) { out.push_back(m); });
}

bool Scanner::tokenizeModules(int line, int b, int e, const std::function<void(const RawModule&)>& each) {
  const std::string& s = clean_[line - 1];
  RawModule m;
  int i = b;
  bool ok = true;
  while (i < e) {
    if (isSpace(s[i])) { ++i; continue; }
    char c = s[i];
    if (c == '(' || c == ')') {
      error(line, i, c == ')' ? "unmatched ')'" : std::string("unexpected '") + c + "' (parameters must follow a module name)");
      return false;
    }
    m.col = i;
    m.args.clear();
    m.hasParens = false;
    // cpfg's lexer drops blanks between symbols, and its string holds one character per
    // symbol: '@ Tx(1)' is '@Tx(1)'. So in a .l file blanks may part '@' from its letters.
    int rest = i + 1;
    if (c == '@' && dialect_ == Dialect::Cpfg)
      while (rest < e && isSpace(s[rest])) ++rest;
    size_t best = 0;
    for (const std::string& name : multiNames_)
      if (name[0] == c && name.size() > best && static_cast<int>(name.size()) - 1 <= e - rest &&
          s.compare(rest, name.size() - 1, name, 1, std::string::npos) == 0)
        best = name.size();
    if (best) {
      m.name.assign(1, c);
      m.name.append(s, rest, best - 1);
      i = rest + static_cast<int>(best) - 1;
    } else if (c == '~' && i + 1 < e && std::isalpha(static_cast<unsigned char>(s[i + 1]))) {
      m.name.assign(s, i, 2);
      i += 2;
    } else {
      m.name.assign(1, c);
      ++i;
    }
    int j = i;
    while (j < e && isSpace(s[j])) ++j;
    if (j < e && s[j] == '(') {
      m.hasParens = true;
      int depth = 0;
      int argStart = j + 1;
      int k = j;
      bool quoted = false;  // cpfg's @L("format", ...): a string may hold ( ) and ,
      for (; k < e; ++k) {
        if (s[k] == '"') quoted = !quoted;
        if (quoted) continue;
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
    const size_t nameEnd = static_cast<size_t>(m.col) + m.name.size();
    if (dialect_ == Dialect::Cpfg && !m.name.empty() && m.name[0] == '~') {
      // cpfg's `~X` draws the view file's surface X (the letter after `~`).
      const char id = m.name.size() > 1 ? m.name[1] : nameEnd < s.size() ? s[nameEnd] : '\0';
      if (id == '\0' || id == ' ' || id == '\t') {
        error(line, m.col, "cpfg's '~' must be followed by a surface id (the letter of a view file's 'surface:' line)");
        return false;
      }
      if (cpfgUndrawnSurfaceIds_.find(id) != std::string::npos) {
        error(line, m.col, std::string("cpfg's '~") + id + "' names the view file's 'tsurface: " + id +
                               " ...' (a triangulated surface), which is not supported");
        return false;
      }
      if (cpfgSurfaceIds_.find(id) == std::string::npos && warnedSurfaceIds_.find(id) == std::string::npos) {
        // cpfg draws nothing for a surface id it has not read (patches.c: FindSurfaceIndex
        // returns -1; the turtle does not move), and neither does Sprig: a warning.
        warnedSurfaceIds_ += id;
        auto [loc, text] = locate(line, m.col);
        diags_.warning(loc, std::string("cpfg's '~") + id + "' names no surface (" +
                                (cpfgSurfaceIds_.empty() ? std::string("there is no view file with a 'surface:' line")
                                                         : "the view file has no 'surface: " + std::string(1, id) + " ...' line; it defines '" + cpfgSurfaceIds_ + "'") +
                                "): it draws nothing, as in cpfg", std::move(text));
      }
    }
    if (auto why = cpfgUnsupported(m.name, m.args.size(), m.hasParens, nameEnd < s.size() ? s[nameEnd] : '\0', dialect_)) {
      error(line, m.col, *why);
      return false;
    }
    each(m);
  }
  return ok;
}

std::string Scanner::moduleText(int line, const RawModule& m) const {
  if (!m.hasParens) return m.name;
  const std::string& s = clean_[line - 1];
  int end = m.args.empty() ? static_cast<int>(s.find(')', m.col)) : m.args.back().e;
  return s.substr(m.col, end + 1 - m.col);
}

std::optional<Header> Scanner::headerOf(const std::string& s, int b) {
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

int Scanner::firstNonSpace(const std::string& s) {
  int i = 0;
  while (i < static_cast<int>(s.size()) && isSpace(s[i])) ++i;
  return i;
}

std::pair<int, int> Scanner::findArrow(const std::string& s) {
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

int Scanner::findTop(int line, int b, int e, char c) const {
  const std::string& s = clean_[line - 1];
  int depth = 0;
  for (int i = b; i < e; ++i) {
    if (s[i] == '(') ++depth;
    else if (s[i] == ')') --depth;
    else if (depth == 0 && s[i] == c) return i;
  }
  return -1;
}

int Scanner::findTopLast(int line, int b, int e, char c) const {
  // A hit is at depth 0, so the search may go on from the next character.
  int found = -1;
  for (int i = findTop(line, b, e, c); i >= 0; i = findTop(line, i + 1, e, c)) found = i;
  return found;
}

}  // namespace sprig::lsystem::detail
