// cpfg's C preprocessor, as cpfg runs it on an L-system file before reading it: `#define`
// of module strings and function-like macros, `#undef`, `#include "file"` of files in the
// object's folder, `#ifdef`/`#ifndef`/`#else`/`#endif`. Part of the Scanner (it produces
// the scanner's lines and remembers where each column was written, so that every error
// points at the user's file:line:col). docs/GRAMMAR.md, "The C preprocessor".

#include <algorithm>
#include <cstdlib>
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

void Scanner::preprocess(int file, const std::vector<std::string>& raw, const std::vector<std::string>& clean, int depth) {
  auto emit = [&](size_t k, std::string text, std::vector<int> map) {
    raw_.push_back(raw[k]);
    clean_.push_back(std::move(text));
    origin_.push_back(Origin{file, static_cast<int>(k) + 1});
    colMap_.push_back(std::move(map));
  };
  auto err = [&](size_t k, size_t col, const std::string& msg) {
    diags_.error(SourceLoc{files_[file], static_cast<int>(k) + 1, static_cast<int>(col) + 1}, msg, raw[k]);
  };
  auto active = [&] { return conditionals_.empty() || conditionals_.back().active; };
  auto defined = [&](const std::string& name) {
    return std::any_of(macros_.begin(), macros_.end(), [&](const auto& m) { return m.first == name; }) ||
           std::any_of(constants_.begin(), constants_.end(), [&](const auto& c) { return c.first == name; });
  };
  const size_t openAtStart = conditionals_.size();
  size_t joinedUntil = 0;  // the last line a directive's backslash continuation took
  for (size_t k = 0; k < clean.size(); ++k) {
    if (k > 0 && k <= joinedUntil) {  // part of the directive above: blank here
      emit(k, "", {});
      continue;
    }
    const std::string* line = &clean[k];
    size_t b = static_cast<size_t>(firstNonSpace(*line));
    // cpp's line splicing: a directive whose line ends in a backslash goes on with the next
    // line (`#define LEAF [+F \` then the rest); the lines it takes stay blank.
    std::string joined;
    if (b < line->size() && (*line)[b] == '#') {
      auto continues = [](const std::string& t) {
        size_t e = t.size();
        while (e > 0 && isSpace(t[e - 1])) --e;
        return e > 0 && t[e - 1] == '\\' ? e : std::string::npos;
      };
      size_t j = k, cut = continues(clean[k]);
      if (cut != std::string::npos) {
        joined = clean[k];
        while (cut != std::string::npos && j + 1 < clean.size()) {
          joined.resize(cut - 1);
          joined += ' ';
          joined += clean[++j];
          cut = continues(joined);
        }
        if (cut != std::string::npos) joined.resize(cut - 1);
        joinedUntil = j;
        line = &joined;
      }
    }
    const std::string& s = *line;
    if (b < s.size() && s[b] == '#') {
      size_t i = b + 1;
      while (i < s.size() && isSpace(s[i])) ++i;
      size_t we = i;
      while (we < s.size() && isIdentChar(s[we])) ++we;
      const std::string word = s.substr(i, we - i);
      size_t ni = we;
      while (ni < s.size() && isSpace(s[ni])) ++ni;
      size_t ne = ni;
      while (ne < s.size() && isIdentChar(s[ne])) ++ne;
      const std::string name = s.substr(ni, ne - ni);
      if (word == "ifdef" || word == "ifndef") {
        if (name.empty() || !isIdentStart(name[0])) err(k, ni, "expected a name after '#" + word + "'");
        bool on = active() && (defined(name) == (word == "ifdef"));
        conditionals_.push_back(Conditional{on, active(), false, file, static_cast<int>(k) + 1, static_cast<int>(b)});
        emit(k, "", {});
        continue;
      }
      if (word == "if") {  // not read: the grammar parser reports it; its #endif still closes it
        conditionals_.push_back(Conditional{active(), active(), false, file, static_cast<int>(k) + 1, static_cast<int>(b)});
        emit(k, s, {});
        continue;
      }
      if (word == "else" || word == "endif") {
        if (conditionals_.size() <= openAtStart) {
          err(k, b, "'#" + word + "' without '#ifdef' or '#ifndef'");
        } else if (word == "endif") {
          conditionals_.pop_back();
        } else if (conditionals_.back().elseSeen) {
          err(k, b, "a second '#else' for the '#if' at line " + std::to_string(conditionals_.back().line));
        } else {
          Conditional& c = conditionals_.back();
          c.elseSeen = true;
          c.active = c.parentActive && !c.active;
        }
        emit(k, "", {});
        continue;
      }
      if (!active()) {
        emit(k, "", {});
        continue;
      }
      if (word == "define" && !name.empty() && isIdentStart(name[0])) {
        Macro m;
        m.file = file;
        m.line = static_cast<int>(k) + 1;
        size_t after = ne;
        if (ne < s.size() && s[ne] == '(') {  // function-like: the '(' right after the name
          size_t close = s.find(')', ne);
          if (close == std::string::npos) {
            err(k, ne, "unclosed '(' in '#define " + name + "('");
            emit(k, "", {});
            continue;
          }
          std::string list = s.substr(ne + 1, close - ne - 1);
          size_t p = 0;
          while (p <= list.size()) {
            size_t c = list.find(',', p);
            if (c == std::string::npos) c = list.size();
            std::string param = trimmed(list.substr(p, c - p), 0);
            if (!param.empty() || c < list.size()) {
              if (param.empty() || !isIdentStart(param[0]) || tokenEnd(param, 0) != param.size())
                err(k, ne + 1 + p, "invalid parameter name '" + param + "' in '#define " + name + "(...)'");
              m.params.push_back(param);
            }
            p = c + 1;
          }
          m.functionLike = true;
          after = close + 1;
        }
        m.body = trimmed(s, after);
        if (!m.functionLike && isConstantBody(m.body, constants_, dialect_)) {
          constants_.emplace_back(name, static_cast<int>(k) + 1);
          emit(k, s, {});  // read by the grammar parser (a value -D may override)
          continue;
        }
        auto prev = std::find_if(macros_.begin(), macros_.end(), [&](const auto& e) { return e.first == name; });
        if (prev != macros_.end() || std::any_of(constants_.begin(), constants_.end(), [&](const auto& c) { return c.first == name; })) {
          err(k, ni, "'" + name + "' is already defined" +
                         (prev != macros_.end() ? " at " + files_[prev->second.file] + ":" + std::to_string(prev->second.line) : ""));
        } else {
          macros_.emplace_back(name, std::move(m));
        }
        emit(k, "", {});
        continue;
      }
      if (word == "undef") {
        macros_.erase(std::remove_if(macros_.begin(), macros_.end(), [&](const auto& e) { return e.first == name; }), macros_.end());
        constants_.erase(std::remove_if(constants_.begin(), constants_.end(), [&](const auto& e) { return e.first == name; }), constants_.end());
        emit(k, "", {});
        continue;
      }
      if (word == "include") {
        emit(k, "", {});
        char open = ni < s.size() ? s[ni] : '\0';
        char closeCh = open == '"' ? '"' : open == '<' ? '>' : '\0';
        size_t close = closeCh ? s.find(closeCh, ni + 1) : std::string::npos;
        if (close == std::string::npos) {
          err(k, ni, "expected a file name in quotes after '#include'");
          continue;
        }
        const std::string target = s.substr(ni + 1, close - ni - 1);
        namespace fs = std::filesystem;
        std::error_code ec;
        fs::path top = fs::path(fileName_).parent_path();
        fs::path root = fs::weakly_canonical(fs::absolute(top.empty() ? fs::path(".") : top, ec), ec);
        fs::path from = fs::path(files_[file]).parent_path();
        fs::path path = fs::weakly_canonical(fs::absolute(from / target, ec), ec);
        fs::path rel = path.lexically_relative(root);
        if (fs::path(target).is_absolute() || rel.empty() || *rel.begin() == "..") {
          err(k, ni, "'#include \"" + target + "\"' is outside the object's folder: only files beside the L-system "
                     "(or in folders below it) may be included");
          continue;
        }
        if (depth + 1 > kMaxIncludeDepth) {
          err(k, ni, "'#include' nested deeper than " + std::to_string(kMaxIncludeDepth) + " files (does a file include itself?)");
          continue;
        }
        std::string text;
        try {
          text = readFile(path);
        } catch (const FileReadError& e) {
          err(k, ni, FileReadError(from / target, e.reason()).what());  // the name as written, not the canonical one
          continue;
        }
        files_.push_back((from / target).lexically_normal().string());
        const int index = static_cast<int>(files_.size()) - 1;
        std::pair<int, int> pending{0, 0};
        std::string cleanText = blankComments(text, pending);
        if (pending.first)
          diags_.error(SourceLoc{files_[index], pending.first, pending.second + 1}, "unterminated comment '/*'");
        preprocess(index, splitAtNewlines(text), splitAtNewlines(cleanText), depth + 1);
        continue;
      }
      emit(k, s, {});  // `#define` without a name and other directives: the grammar parser reports them
      continue;
    }
    if (!active()) {
      emit(k, "", {});
      continue;
    }
    std::vector<int> map;
    std::string text = expand(s, map, file, static_cast<int>(k) + 1, raw[k]);
    emit(k, std::move(text), std::move(map));
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
