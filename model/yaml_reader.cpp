#include "model/yaml_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>

#include "core/atomic_file.h"
#include "core/srgb.h"
#include "core/text.h"
#include "model/detail/key_recorder.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

constexpr int kMaxDepth = 256;

/// Where (1-based line, 0-based column) the nesting of a YAML text first exceeds limit,
/// or line 0 when it never does. yaml-cpp 0.7 parses nesting by recursion and overflows
/// the stack on deep input (a few 10,000 levels), so the text is scanned before it is
/// handed over. Depth counts block levels (distinct indentations), compact sequence
/// entries (`- - x`) and open flow brackets (`[`, `{`) outside quotes and comments;
/// block scalar bodies (`|`, `>`) are skipped. An over-estimate is harmless at 256.
std::pair<int, int> yamlTooDeep(std::string_view text, size_t limit) {
  std::vector<size_t> indents;
  size_t flow = 0;
  char quote = 0;              // the open quote of a scalar running over lines
  size_t blockScalarIndent = std::string_view::npos;  // skip deeper lines after `|` or `>`
  int lineNo = 0;
  size_t pos = 0;
  while (pos <= text.size()) {
    size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++lineNo;
    size_t indent = 0;
    while (indent < line.size() && line[indent] == ' ') ++indent;
    bool blank = indent == line.size() || line[indent] == '#' || line[indent] == '\r';
    if (blockScalarIndent != std::string_view::npos) {
      if (blank || indent > blockScalarIndent) continue;
      blockScalarIndent = std::string_view::npos;
    }
    size_t depth = 0;
    size_t i = indent;
    if (!quote && flow == 0) {
      if (blank) continue;
      while (!indents.empty() && indents.back() > indent) indents.pop_back();
      if (indents.empty() || indents.back() < indent) indents.push_back(indent);
      // Compact nested sequences: each `- ` opens one more level on this line.
      while (i + 1 < line.size() && line[i] == '-' && (line[i + 1] == ' ' || line[i + 1] == '\t')) {
        ++depth;
        i += 2;
        while (i < line.size() && line[i] == ' ') ++i;
        if (indents.size() + depth > limit) return {lineNo, static_cast<int>(i)};
      }
    }
    depth += indents.size();
    char prev = ' ';
    size_t end = line.size();  // end of the line before any comment
    for (; i < line.size(); prev = line[i], ++i) {
      char c = line[i];
      if (quote) {
        if (quote == '"' && c == '\\') ++i;
        else if (c == quote) quote = 0;
        continue;
      }
      bool atToken = prev == ' ' || prev == '\t' || prev == '[' || prev == '{' || prev == ',' || prev == ':' || i == indent;
      if ((c == '"' || c == '\'') && atToken) {
        quote = c;
      } else if (c == '#' && (prev == ' ' || prev == '\t')) {
        end = i;
        break;
      } else if (c == '[' || c == '{') {
        if (depth + ++flow > limit) return {lineNo, static_cast<int>(i)};
      } else if ((c == ']' || c == '}') && flow > 0) {
        --flow;
      }
    }
    if (depth + flow > limit) return {lineNo, static_cast<int>(indent)};
    // A block scalar header (`key: |`, `- >-`, `|2`) ends the line: skip its body.
    std::string_view head = line.substr(0, end);
    while (!head.empty() && (head.back() == ' ' || head.back() == '\t' || head.back() == '\r')) head.remove_suffix(1);
    size_t k = head.find_last_of("|>");
    if (!quote && flow == 0 && k != std::string_view::npos && (k == 0 || head[k - 1] == ' ') &&
        head.find_first_not_of("+-0123456789", k + 1) == std::string_view::npos)
      blockScalarIndent = indent;
  }
  return {0, 0};
}

/// Shortest text of a double that reads back exactly ("0.5", "1000", "1e+20").
std::string formatNumber(double v) {
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string trim(std::string_view s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return std::string(s.substr(b, e - b));
}

bool isNonFiniteWord(std::string_view s) {
  if (!s.empty() && (s[0] == '+' || s[0] == '-')) s.remove_prefix(1);
  static const char* words[] = {".nan", ".NaN", ".NAN", ".inf", ".Inf", ".INF", "nan", "NaN", "NAN",
                                "inf",  "Inf",  "INF",  "infinity", "Infinity", "INFINITY"};
  for (const char* w : words)
    if (s == w) return true;
  return false;
}

/// Parses a whole string as a decimal real number (YAML core schema float, no specials).
std::optional<double> parseReal(std::string_view s) {
  if (s.empty()) return std::nullopt;
  if (s[0] == '+') s.remove_prefix(1);
  if (s.empty() || s[0] == '+') return std::nullopt;
  double v = 0;
  auto res = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  if (res.ec != std::errc() || res.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::string rangeText(double v, double lo, double hi) {
  std::string out = formatNumber(v) + ", ";
  bool hasLo = std::isfinite(lo), hasHi = std::isfinite(hi);
  if (hasLo && hasHi) return out + "out of range [" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
  if (hasLo) return out + "must be at least " + formatNumber(lo);
  return out + "must be at most " + formatNumber(hi);
}

const char* kindName(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Sequence: return "a sequence";
    case YAML::NodeType::Null: return "nothing";
    case YAML::NodeType::Scalar: return "a scalar";
    default: return "nothing";
  }
}

/// "got 'text'" for scalars, "got a map" otherwise.
std::string gotText(const YNode& n) {
  if (n.isScalar()) return "got '" + n.node().Scalar() + "'";
  return std::string("got ") + kindName(n.node());
}

/// Walks the document once: counts nodes (aliases count every time they are reached),
/// limits depth and reports duplicate keys.
class Walker {
 public:
  Walker(const YamlFile& file, DiagnosticList& diags, int64_t maxNodes)
      : file_(file), diags_(diags), maxNodes_(maxNodes) {}

  /// False when the cap on nodes or depth was hit (an error was added).
  bool walk(const YAML::Node& n, int depth) {
    if (++visited_ > maxNodes_) {
      file_.error(diags_, n.Mark(),
                  "YAML document has more than " + std::to_string(maxNodes_) + " nodes (alias bomb?)");
      return false;
    }
    if (depth > kMaxDepth) {
      file_.error(diags_, n.Mark(), "YAML document nests deeper than " + std::to_string(kMaxDepth) + " levels (the limit)");
      return false;
    }
    if (n.IsSequence()) {
      for (const auto& child : n)
        if (!walk(child, depth + 1)) return false;
    } else if (n.IsMap()) {
      std::map<std::string, int, std::less<>> firstLine;
      for (auto it = n.begin(); it != n.end(); ++it) {
        // A copy, not a reference: yaml-cpp's iterator returns a temporary from operator->,
        // so a reference to its `first` dangles at the end of this statement.
        const YAML::Node key = it->first;
        if (!key.IsScalar()) {
          report(key.Mark(), "map keys must be plain text, got " + std::string(kindName(key)));
        } else {
          int line = key.Mark().line + 1;
          auto [pos, fresh] = firstLine.emplace(key.Scalar(), line);
          if (!fresh)
            report(key.Mark(), "duplicate key '" + key.Scalar() + "' (first defined at line " +
                                   std::to_string(pos->second) + ")");
        }
        if (!walk(key, depth + 1) || !walk(it->second, depth + 1)) return false;
      }
    }
    return true;
  }

 private:
  /// Adds an error once per position (aliased maps are walked more than once).
  void report(const YAML::Mark& mark, std::string message) {
    if (reported_.insert({mark.line, mark.column}).second) file_.error(diags_, mark, std::move(message));
  }

  const YamlFile& file_;
  DiagnosticList& diags_;
  int64_t maxNodes_;
  int64_t visited_ = 0;
  std::set<std::pair<int, int>> reported_;
};

/// The first line (1-based) whose indentation holds a tab, with the tab's 0-based column,
/// or line 0. YAML indents with spaces only; yaml-cpp reports such a line as some other
/// syntax error ("illegal map value", "end of map not found") that never names the tab.
std::pair<int, int> firstIndentTab(std::string_view text) {
  int lineNo = 1;
  for (size_t pos = 0; pos < text.size(); ++lineNo) {
    size_t nl = text.find('\n', pos);
    std::string_view line = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() : nl + 1;
    size_t i = line.find_first_not_of(" \t");
    if (i == std::string_view::npos || line[i] == '#' || line[i] == '\r') continue;
    if (size_t tab = line.substr(0, i).find('\t'); tab != std::string_view::npos) return {lineNo, static_cast<int>(tab)};
  }
  return {0, 0};
}

/// yaml-cpp's terse syntax message with what usually causes it.
std::string explainYamlError(const std::string& msg) {
  static const std::pair<const char*, const char*> kHints[] = {
      {"illegal map value", "a ':' where no key can start (a value holding ': ' needs quotes)"},
      {"end of map not found", "a key is indented differently from the keys beside it"},
      {"end of map flow not found", "a '{' is not closed by '}'"},
      {"end of sequence flow not found", "a '[' is not closed by ']'"},
      {"end of sequence not found", "a '- ' item is indented differently from the items beside it"},
  };
  for (auto [m, hint] : kHints)
    if (msg == m) return msg + ": " + hint;
  return msg;
}

}  // namespace

// ---- YamlFile ---------------------------------------------------------------------

std::shared_ptr<const YamlFile> YamlFile::load(const fs::path& path, DiagnosticList& diags,
                                               const YamlLoadOptions& options) {
  std::string display = path.string();
  std::string text;
  try {
    text = readFile(path, options.maxBytes);
  } catch (const FileReadError& e) {
    const bool tooLarge = e.reason().find("the limit of") != std::string::npos;
    diags.error(SourceLoc{display, 0, 0},
                tooLarge ? "file is larger than " + std::to_string(options.maxBytes) + " bytes" : e.reason());
    return nullptr;
  }
  return parseAt(std::move(text), display, path, diags, options);
}

std::shared_ptr<const YamlFile> YamlFile::parse(std::string text, std::string displayPath, DiagnosticList& diags,
                                                const YamlLoadOptions& options) {
  fs::path path(displayPath);
  return parseAt(std::move(text), std::move(displayPath), path, diags, options);
}

std::shared_ptr<const YamlFile> YamlFile::parseAt(std::string text, std::string displayPath, const fs::path& path,
                                                  DiagnosticList& diags, const YamlLoadOptions& options) {
  auto file = std::shared_ptr<YamlFile>(new YamlFile());
  file->path_ = path;
  file->displayPath_ = std::move(displayPath);
  file->text_ = std::move(text);
  file->self_ = file;
  if (!checkText(file->text_, file->displayPath_, "a YAML file", diags)) return nullptr;
  if (auto [line, col] = yamlTooDeep(file->text_, kMaxDepth); line > 0) {
    diags.error(SourceLoc{file->displayPath_, line, col + 1},
                "YAML document nests deeper than " + std::to_string(kMaxDepth) + " levels (the limit)", file->sourceLine(line));
    return nullptr;
  }
  try {
    file->root_ = YAML::Load(file->text_);
  } catch (const YAML::Exception& e) {
    if (auto [line, col] = firstIndentTab(file->text_); line > 0) {
      diags.error(SourceLoc{file->displayPath_, line, col + 1},
                  "YAML syntax error: a tab in the indentation (YAML indents with spaces only)", file->sourceLine(line));
      return nullptr;
    }
    YAML::Mark mark = e.mark;
    if (mark.line < 0) mark.line = 0, mark.column = 0;
    file->error(diags, mark, "YAML syntax error: " + explainYamlError(e.msg));
    return nullptr;
  }
  Walker walker(*file, diags, options.maxNodes);
  if (!walker.walk(file->root_, 0)) return nullptr;
  return file;
}

YNode YamlFile::rootNode() const { return YNode(self_.lock(), root_); }

SourceLoc YamlFile::loc(const YAML::Mark& mark) const {
  if (mark.line < 0) return SourceLoc{displayPath_, 0, 0};
  return SourceLoc{displayPath_, mark.line + 1, mark.column + 1};
}

void YamlFile::error(DiagnosticList& diags, const YAML::Mark& mark, std::string message) const {
  SourceLoc l = loc(mark);
  diags.error(l, std::move(message), sourceLine(l.line));
}

// ---- YNode ------------------------------------------------------------------------

// ---- Describe mode (`sprig schema`, model/detail/key_recorder.h) ------------------------

namespace detail {

namespace {
thread_local KeyRecorder* tActiveRecorder = nullptr;
}

void KeySchema::range(double lo, double hi) {
  if (std::isfinite(lo)) min = min ? std::min(*min, lo) : lo;
  if (std::isfinite(hi)) max = max ? std::max(*max, hi) : hi;
}

KeyRecorder* KeyRecorder::active() { return tActiveRecorder; }

KeyRecorder::KeyRecorder(KeySchema& root, int pass) : root_(&root), pass_(pass), previous_(tActiveRecorder) {
  tActiveRecorder = this;
}

uint64_t KeyRecorder::nextRandom() {
  uint64_t z = (static_cast<uint64_t>(pass_) << 32) + ++questions_ * 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

bool KeyRecorder::answerHas() {
  if (pass_ < 2) return pass_ == 0;
  return nextRandom() & 1;
}

std::optional<size_t> KeyRecorder::chooseAlternative(size_t n) {
  if (n == 0 || descents_ >= kMaxDescents) return std::nullopt;
  ++descents_;
  return static_cast<size_t>(nextRandom() % n);
}

std::optional<YAML::Node> KeyRecorder::answered(const KeySchema* at, bool& wasAbsent) const {
  auto it = answers_.find(at);
  wasAbsent = it != answers_.end() && !it->second;
  if (it == answers_.end() || !it->second) return std::nullopt;
  return it->second;
}

void KeyRecorder::remember(const KeySchema* at, std::optional<YAML::Node> answer) { answers_[at] = std::move(answer); }

KeySchema* KeyRecorder::definition(const std::string& name) {
  if (!definitions_) return nullptr;
  auto& d = (*definitions_)[name];
  if (!d) d = std::make_unique<KeySchema>();
  return d.get();
}

KeyRecorder::~KeyRecorder() { tActiveRecorder = previous_; }

KeySchema* KeyRecorder::schemaOf(const YAML::Node& node, bool asRoot) {
  for (auto& [n, s] : bound_)
    if (n.is(node)) return s;
  if (asRoot && root_) {
    KeySchema* r = root_;
    root_ = nullptr;
    bind(node, *r);
    return r;
  }
  return nullptr;
}

void KeyRecorder::bind(const YAML::Node& node, KeySchema& schema) {
  for (auto& [n, s] : bound_)
    if (n.is(node)) {
      s = &schema;
      return;
    }
  bound_.emplace_back(node, &schema);
}

YAML::Node KeyRecorder::placeholder() {
  const uint64_t r = pass_ < 2 ? 0 : nextRandom() % 4;
  if (r == 2) placeholders_.emplace_back(std::string("0"));  // a number, an integer, a text, an expression
  else if (r == 3) placeholders_.emplace_back(YAML::NodeType::Sequence);
  else placeholders_.emplace_back(YAML::NodeType::Map);
  return placeholders_.back();
}

bool KeyRecorder::isPlaceholder(const YAML::Node& node) const {
  for (const auto& p : placeholders_)
    if (p.is(node)) return true;
  return false;
}

}  // namespace detail

namespace {

/// The schema node of n while describing, else null (the one test on every real read).
detail::KeySchema* describing(const YAML::Node& n) {
  detail::KeyRecorder* r = detail::KeyRecorder::active();
  return r ? r->schemaOf(n) : nullptr;
}

/// Typed reads under way on this thread: scalar() records "string" only outside them (a
/// reader that takes a node's text itself accepts a scalar there).
thread_local int tTypedReads = 0;
struct TypedRead {
  TypedRead() { ++tTypedReads; }
  ~TypedRead() { --tTypedReads; }
  TypedRead(const TypedRead&) = delete;
  TypedRead& operator=(const TypedRead&) = delete;
};

void noteType(const YAML::Node& n, const char* type, double lo = -HUGE_VAL, double hi = HUGE_VAL) {
  if (detail::KeySchema* s = describing(n)) {
    s->types.insert(type);
    s->range(lo, hi);
  }
}

/// Describing, and n stands for an absent key: a typed read records its type and then
/// succeeds with a neutral value, so the reader goes on to the keys after it (a blob node's
/// `hi` after its `lo`) instead of stopping at its first error.
bool describedPlaceholder(const YAML::Node& n) {
  detail::KeyRecorder* r = detail::KeyRecorder::active();
  return r && r->isPlaceholder(n) && r->schemaOf(n);
}

double neutral(double min, double max) { return std::max(min, std::min(1.0, max)); }

std::string jsonNumber(double v) {
  std::ostringstream o;
  o.precision(9);
  o << v;
  return o.str();
}

/// The shortest text that reads back as the same float (0.3f is "0.3", not "0.300000012").
std::string jsonFloat(float v) {
  char buffer[32];
  return std::string(buffer, std::to_chars(buffer, buffer + sizeof buffer, v).ptr);
}

std::string jsonVec3(const Vec3& v) {
  return "[" + jsonFloat(v.x) + ", " + jsonFloat(v.y) + ", " + jsonFloat(v.z) + "]";
}

}  // namespace

std::string detail::jsonString(std::string_view text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') out += '\\', out += c;
    else if (c == '\n') out += "\\n";
    else if (static_cast<unsigned char>(c) < 0x20) out += ' ';
    else out += c;
  }
  return out + "\"";
}

std::string YNode::scalar() const {
  if (tTypedReads == 0 && node_.IsScalar())
    if (detail::KeySchema* s = describing(node_)) s->types.insert("string");
  return node_.IsScalar() ? node_.Scalar() : std::string();
}

std::vector<YNode> YNode::items() const {
  if (detail::KeySchema* s = describing(node_)) {
    s->types.insert("sequence");
    std::vector<YNode> out;
    if (!node_.IsSequence()) return out;
    detail::KeyRecorder* r = detail::KeyRecorder::active();
    if (r->isPlaceholder(node_) && node_.size() == 0) {  // describing: one placeholder element
      YAML::Node element = r->placeholder();
      r->bind(element, s->item());
      out.emplace_back(file_, element);
      return out;
    }
    for (const auto& child : node_) {
      detail::KeyRecorder::active()->bind(child, s->item());
      out.emplace_back(file_, child);
    }
    return out;
  }
  std::vector<YNode> out;
  if (!node_.IsSequence()) return out;
  for (const auto& child : node_) out.emplace_back(file_, child);
  return out;
}

std::vector<std::pair<YNode, YNode>> YNode::pairs() const {
  // A reader walking a map's pairs itself treats its keys as data (material names, defines).
  if (tTypedReads == 0)
    if (detail::KeySchema* s = describing(node_)) s->dataKeys = true;
  std::vector<std::pair<YNode, YNode>> out;
  if (!node_.IsMap()) return out;
  for (auto it = node_.begin(); it != node_.end(); ++it)
    out.emplace_back(YNode(file_, it->first), YNode(file_, it->second));
  return out;
}

std::optional<double> YNode::asNumber(DiagnosticList& diags, std::string_view what, double min, double max) const {
  TypedRead typedRead;
  noteType(node_, "number", min, max);
  if (describedPlaceholder(node_)) return neutral(min, max);
  if (!isScalar()) {
    error(diags, std::string(what) + " must be a number, " + gotText(*this));
    return std::nullopt;
  }
  std::string text = trim(scalar());
  if (isPlainScalar() && isNonFiniteWord(text)) {
    error(diags, std::string(what) + " must be a finite number, got '" + text + "'");
    return std::nullopt;
  }
  auto v = isPlainScalar() ? parseReal(text) : std::nullopt;
  if (!v) {
    error(diags, std::string(what) + " must be a number, got " + (isPlainScalar() ? "'" : "string '") + scalar() + "'");
    return std::nullopt;
  }
  if (!std::isfinite(*v)) {
    error(diags, std::string(what) + " must be a finite number, got '" + text + "'");
    return std::nullopt;
  }
  if (*v < min || *v > max) {
    error(diags, std::string(what) + " is " + rangeText(*v, min, max));
    return std::nullopt;
  }
  return v;
}

std::optional<int64_t> YNode::asInteger(DiagnosticList& diags, std::string_view what, int64_t min,
                                        int64_t max) const {
  TypedRead typedRead;
  noteType(node_, "integer", min == std::numeric_limits<int64_t>::min() ? -HUGE_VAL : double(min),
           max == std::numeric_limits<int64_t>::max() ? HUGE_VAL : double(max));
  if (describedPlaceholder(node_)) return std::max(min, std::min<int64_t>(1, max));
  if (!isScalar()) {
    error(diags, std::string(what) + " must be an integer, " + gotText(*this));
    return std::nullopt;
  }
  std::string text = trim(scalar());
  std::string_view s = text;
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  int64_t v = 0;
  auto res = std::from_chars(s.data(), s.data() + s.size(), v);
  bool ok = isPlainScalar() && !s.empty() && res.ec == std::errc() && res.ptr == s.data() + s.size();
  if (!ok && isPlainScalar()) {
    // Accept integral reals written as 1e3; refuse 2.5 and anything out of int64 range.
    auto r = parseReal(text);
    if (r && std::isfinite(*r) && std::floor(*r) == *r && std::fabs(*r) < 9.0e18) {
      v = static_cast<int64_t>(*r);
      ok = true;
    }
  }
  if (!ok) {
    error(diags, std::string(what) + " must be an integer, got " + (isPlainScalar() ? "'" : "string '") + scalar() + "'");
    return std::nullopt;
  }
  if (v < min || v > max) {
    std::string range;
    bool hasLo = min != std::numeric_limits<int64_t>::min(), hasHi = max != std::numeric_limits<int64_t>::max();
    if (hasLo && hasHi)
      range = "out of range [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    else if (hasLo)
      range = "must be at least " + std::to_string(min);
    else
      range = "must be at most " + std::to_string(max);
    error(diags, std::string(what) + " is " + std::to_string(v) + ", " + range);
    return std::nullopt;
  }
  return v;
}

std::optional<bool> YNode::asBoolean(DiagnosticList& diags, std::string_view what) const {
  TypedRead typedRead;
  noteType(node_, "boolean");
  if (describedPlaceholder(node_)) return false;
  if (isPlainScalar()) {
    const std::string s = trim(scalar());
    static const char* yes[] = {"true", "True", "TRUE", "yes", "Yes", "YES", "on", "On", "ON"};
    static const char* no[] = {"false", "False", "FALSE", "no", "No", "NO", "off", "Off", "OFF"};
    for (const char* w : yes)
      if (s == w) return true;
    for (const char* w : no)
      if (s == w) return false;
  }
  error(diags, std::string(what) + " must be true or false, " + gotText(*this));
  return std::nullopt;
}

std::optional<std::string> YNode::asString(DiagnosticList& diags, std::string_view what) const {
  TypedRead typedRead;
  noteType(node_, "string");
  if (!isScalar()) {
    error(diags, std::string(what) + " must be a string, " + gotText(*this));
    return std::nullopt;
  }
  return scalar();
}

std::optional<Vec3> YNode::asVec3(DiagnosticList& diags, std::string_view what, double min, double max) const {
  TypedRead typedRead;
  noteType(node_, "vec3", min, max);
  if (describedPlaceholder(node_)) return Vec3(static_cast<float>(neutral(min, max)));
  if (!isSequence() || node_.size() != 3) {
    std::string got = isSequence() ? "got " + std::to_string(node_.size()) + " elements" : gotText(*this);
    error(diags, std::string(what) + " must be [x, y, z], " + got);
    return std::nullopt;
  }
  Vec3 out(0.0f);
  bool ok = true;
  auto elems = items();
  for (int i = 0; i < 3; ++i) {
    const std::string element = std::string(what) + "[" + std::to_string(i) + "]";
    auto v = elems[i].asNumber(diags, element, min, max);
    if (v && !(std::abs(*v) <= double(std::numeric_limits<float>::max()))) {
      // A point is kept in single precision: a larger number would become infinite.
      elems[i].error(diags, element + " is " + elems[i].scalar() + ", beyond single precision (at most 3.4e+38 in magnitude)");
      v.reset();
    }
    if (v)
      out[i] = static_cast<float>(*v);
    else
      ok = false;
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<Vec3> YNode::asColor(DiagnosticList& diags, std::string_view what) const {
  TypedRead typedRead;
  noteType(node_, "color");
  if (describedPlaceholder(node_)) return Vec3(0.0f);
  if (isScalar()) {
    const std::string s = trim(scalar());
    auto hex = [](char c) -> int {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      return -1;
    };
    bool ok = s.size() == 7 && s[0] == '#';
    Vec3 c(0.0f);
    for (int i = 0; ok && i < 3; ++i) {
      int hi = hex(s[1 + 2 * i]), lo = hex(s[2 + 2 * i]);
      if (hi < 0 || lo < 0) ok = false;
      else c[i] = srgbToLinear(static_cast<float>(hi * 16 + lo) / 255.0f);
    }
    if (ok) return c;
    error(diags, std::string(what) + " must be a colour [r, g, b] in [0, 1] or \"#rrggbb\", got '" + s + "'");
    return std::nullopt;
  }
  if (isSequence()) return asVec3(diags, what, 0.0, 1.0);
  error(diags, std::string(what) + " must be a colour [r, g, b] in [0, 1] or \"#rrggbb\", " + gotText(*this));
  return std::nullopt;
}

// ---- File references ---------------------------------------------------------------

std::optional<fs::path> resolveReference(const YNode& at, std::string_view ref, const PathPolicy& policy,
                                         DiagnosticList& diags, bool mustExist) {
  const std::string r(ref);
  if (r.empty()) {
    at.error(diags, "empty file reference");
    return std::nullopt;
  }
  static const std::regex uri(R"(^[A-Za-z][A-Za-z0-9+.\-]+:)");
  if (std::regex_search(r, uri)) {
    at.error(diags, "refusing URI '" + r + "': only local files can be referenced");
    return std::nullopt;
  }
  fs::path p(r);
  fs::path base = at.file().path().parent_path();
  fs::path resolved = p.is_absolute() ? p.lexically_normal() : (base / p).lexically_normal();
  if (resolved.empty()) resolved = ".";
  if (std::string refusal = pathRefusal(r, resolved, policy); !refusal.empty()) {
    at.error(diags, refusal);
    return std::nullopt;
  }
  if (mustExist) {
    if (std::string reason = notRegularFileReason(resolved); !reason.empty()) {
      at.error(diags, FileReadError(r, reason).what() + std::string(" (looked for '") + resolved.string() + "')");
      return std::nullopt;
    }
  }
  return resolved;
}

std::string pathRefusal(const std::string& written, const fs::path& resolved, const PathPolicy& policy) {
  if (policy.allowOutside) return {};
  if (fs::path(written).is_absolute())
    return "refusing absolute path '" + written + "' (write it relative to the species file, or pass --allow-outside-paths)";
  // Both sides absolute before weakly_canonical: of a relative path that does not exist it
  // returns the path unchanged, which no absolute root contains.
  std::error_code ec;
  const fs::path rootPath = policy.root.empty() ? fs::path(".") : policy.root;
  fs::path root = fs::weakly_canonical(fs::absolute(rootPath, ec), ec);
  fs::path full = fs::weakly_canonical(fs::absolute(resolved, ec), ec);
  fs::path rel = full.lexically_relative(root);
  if (rel.empty() || *rel.begin() == "..")
    return "refusing path '" + written + "': it leaves the library root '" + rootPath.string() +
           "' (pass --root FOLDER to read from a wider root, or --allow-outside-paths)";
  return {};
}

namespace {

/// p.lexically_normal() without the trailing separator `a/b/..` leaves ("a/"); "." for empty.
fs::path normalFolder(const fs::path& p) {
  fs::path n = p.lexically_normal();
  if (!n.has_filename() && n.has_relative_path()) n = n.parent_path();
  return n.empty() ? fs::path(".") : n;
}

}  // namespace

fs::path defaultLibraryRoot(const fs::path& speciesPath) {
  std::error_code ec;
  const fs::path start = fs::is_directory(speciesPath, ec) ? speciesPath : speciesPath.parent_path();
  fs::path spelled = start.empty() ? fs::path(".") : start;  // the candidate as the user spelled it
  fs::path dir = fs::weakly_canonical(fs::absolute(spelled, ec), ec);
  for (int up = 0; up < 256 && !dir.empty(); ++up) {
    if (fs::is_regular_file(dir / ".sprig-root", ec)) return normalFolder(spelled);
    if (dir.filename() == "species") return normalFolder(spelled / "..");
    if (dir == dir.parent_path()) break;
    dir = dir.parent_path();
    spelled /= "..";
  }
  return normalFolder(start);
}

// ---- MapReader ---------------------------------------------------------------------

MapReader::MapReader(YNode node, DiagnosticList& diags, std::string context)
    : node_(std::move(node)), diags_(&diags), context_(std::move(context)) {
  TypedRead ownPairs;  // the pairs() below are the reader's index, not keys as data
  if (detail::KeyRecorder* r = detail::KeyRecorder::active()) {
    schema_ = r->schemaOf(node_.node(), true);
    if (schema_) {
      schema_->types.insert("map");
      if (schema_->context.empty()) schema_->context = context_;
    }
  }
  if (node_.isMap()) {
    for (auto& [k, v] : node_.pairs()) {
      if (!k.isScalar()) continue;  // reported when the file was loaded
      std::string name = k.scalar();
      if (index_.count(name)) continue;  // duplicate: reported when the file was loaded
      index_.emplace(name, entries_.size());
      entries_.push_back(Entry{k, v});
    }
  } else if (!node_.isNull() && node_.node().IsDefined()) {
    node_.error(diags, context_ + " must be a map, " + gotText(node_));
  }
}

bool MapReader::has(std::string_view key) const {
  if (schema_) return detail::KeyRecorder::active()->answerHas();
  return index_.find(key) != index_.end();
}

std::optional<YNode> MapReader::get(Key key) {
  known_.emplace(key.name);
  auto it = index_.find(key.name);
  if (schema_) {  // describing: an absent key reads as a placeholder, or stays absent
    detail::KeyRecorder* r = detail::KeyRecorder::active();
    detail::KeySchema& child = schema_->property(std::string(key.name));
    if (child.help.empty()) child.help = key.help;
    YAML::Node n;
    if (it == index_.end()) {  // the same answer each time this pass asks (axisOf reads twice)
      bool wasAbsent = false;
      if (auto again = r->answered(&child, wasAbsent)) return YNode(node_.fileHandle(), *again);
      if (wasAbsent) return std::nullopt;
      if (!r->answerHas()) {
        r->remember(&child, std::nullopt);
        return std::nullopt;
      }
      n = r->placeholder();
      r->remember(&child, n);
    } else {
      n = entries_[it->second].value.node();
    }
    r->bind(n, child);
    return YNode(node_.fileHandle(), n);
  }
  if (it == index_.end()) return std::nullopt;
  return entries_[it->second].value;
}

std::optional<YNode> MapReader::keyNode(std::string_view key) const {
  auto it = index_.find(key);
  if (it == index_.end()) return std::nullopt;
  return entries_[it->second].key;
}

void MapReader::allow(std::initializer_list<Key> keys) {
  for (const Key& k : keys) {
    known_.emplace(k.name);
    if (schema_) {
      detail::KeySchema& p = schema_->property(std::string(k.name));
      if (p.help.empty()) p.help = k.help;
    }
  }
}

std::string quoted(std::string_view key) {
  std::string out;
  out.reserve(key.size() + 2);
  out.push_back('\'');
  out.append(key);
  out.push_back('\'');
  return out;
}

double MapReader::number(Key key, double def, double min, double max) {
  // A float default the reader widened to double (0.3f) reads as the float's shortest text (0.3).
  if (schema_)
    schema_->property(std::string(key.name)).defaultJson =
        jsonNumber(std::isfinite(def) && double(float(def)) == def ? std::stod(jsonFloat(float(def))) : def);
  auto v = get(key);
  if (!v) return def;
  return v->asNumber(*diags_, quoted(key.name), min, max).value_or(def);
}

int64_t MapReader::integer(Key key, int64_t def, int64_t min, int64_t max) {
  if (schema_) schema_->property(std::string(key.name)).defaultJson = std::to_string(def);
  auto v = get(key);
  if (!v) return def;
  return v->asInteger(*diags_, quoted(key.name), min, max).value_or(def);
}

std::string MapReader::string(Key key, std::string def) {
  if (schema_ && !def.empty()) schema_->property(std::string(key.name)).defaultJson = detail::jsonString(def);
  auto v = get(key);
  if (!v) return def;
  return v->asString(*diags_, quoted(key.name)).value_or(def);
}

void MapReader::markRequired(std::string_view key) {
  if (schema_) schema_->required.insert(std::string(key));
}

std::optional<std::string> MapReader::requiredString(Key key) {
  if (schema_) schema_->required.insert(std::string(key.name));
  auto v = get(key);
  if (!v) {
    node_.error(*diags_, "missing required key '" + std::string(key.name) + "' in " + context_);
    return std::nullopt;
  }
  return v->asString(*diags_, quoted(key.name));
}

bool MapReader::boolean(Key key, bool def) {
  if (schema_) schema_->property(std::string(key.name)).defaultJson = def ? "true" : "false";
  auto v = get(key);
  if (!v) return def;
  return v->asBoolean(*diags_, quoted(key.name)).value_or(def);
}

Vec3 MapReader::vec3(Key key, Vec3 def, double min, double max) {
  if (schema_) schema_->property(std::string(key.name)).defaultJson = jsonVec3(def);
  auto v = get(key);
  if (!v) return def;
  return v->asVec3(*diags_, quoted(key.name), min, max).value_or(def);
}

Vec3 MapReader::color(Key key, Vec3 def) {
  if (schema_) schema_->property(std::string(key.name)).defaultJson = jsonVec3(def);
  auto v = get(key);
  if (!v) return def;
  return v->asColor(*diags_, quoted(key.name)).value_or(def);
}

std::string MapReader::choice(Key key, std::string def, const std::vector<std::string>& choices) {
  if (schema_) {
    detail::KeySchema& k = schema_->property(std::string(key.name));
    for (const auto& c : choices)
      if (std::find(k.choices.begin(), k.choices.end(), c) == k.choices.end()) k.choices.push_back(c);
    if (!def.empty()) k.defaultJson = detail::jsonString(def);
  }
  auto v = get(key);
  if (!v) return def;
  auto s = v->asString(*diags_, quoted(key.name));
  if (!s) return def;
  for (const auto& c : choices)
    if (c == *s) return *s;
  std::string list;
  for (size_t i = 0; i < choices.size(); ++i) list += (i ? ", " : "") + choices[i];
  v->error(*diags_, quoted(key.name) + " must be one of " + list + ", got '" + *s + "'" + didYouMean(*s, choices));
  return def;
}

std::optional<YNode> MapReader::section(Key key) {
  if (schema_) schema_->property(std::string(key.name)).types.insert("map");
  auto v = get(key);
  if (!v) return std::nullopt;
  if (!v->isMap()) {
    v->error(*diags_, quoted(key.name) + " must be a map, " + gotText(*v));
    return std::nullopt;
  }
  return v;
}

std::vector<YNode> MapReader::sequence(Key key) {
  auto v = get(key);
  if (!v) return {};
  if (schema_ && detail::KeyRecorder::active()->isPlaceholder(v->node())) {  // describing: one placeholder element
    detail::KeyRecorder* r = detail::KeyRecorder::active();
    detail::KeySchema& s = schema_->property(std::string(key.name));
    s.types.insert("sequence");
    YAML::Node element = r->placeholder();
    r->bind(element, s.item());
    return {YNode(node_.fileHandle(), element)};
  }
  if (!v->isSequence()) {
    v->error(*diags_, quoted(key.name) + " must be a sequence, " + gotText(*v));
    return {};
  }
  return v->items();
}

std::optional<fs::path> MapReader::path(Key key, const PathPolicy& policy, bool mustExist) {
  auto v = get(key);
  if (!v) return std::nullopt;
  auto s = v->asString(*diags_, quoted(key.name));
  if (!s) return std::nullopt;
  return resolveReference(*v, *s, policy, *diags_, mustExist);
}

void MapReader::finish() {
  if (schema_) schema_->closed = true, ++schema_->finishes;
  std::vector<std::string> candidates(known_.begin(), known_.end());
  for (const auto& e : entries_) {
    const std::string name = e.key.scalar();
    if (known_.count(name)) continue;
    if (name == "operations") {
      // Simulation tools act on tetrahedral solids only; say so rather than "unknown key".
      static const std::set<std::string> kinds = {"tree", "shell", "organism", "blob"};
      const std::string where = kinds.count(context_)
                                    ? std::string("this is ") + (context_ == "organism" ? "an " : "a ") + context_
                                    : "not in " + context_;
      e.key.error(*diags_, "'operations' belong to solid species, under 'solid:' (" + where + ")");
      continue;
    }
    e.key.error(*diags_, "unknown key '" + name + "' in " + context_ + didYouMean(name, candidates));
  }
}

std::optional<std::pair<YNode, YNode>> describeOneKey(const YNode& node, const std::vector<std::string>& names,
                                                      const std::string& definition) {
  detail::KeySchema* s = describing(node.node());
  if (!s) return std::nullopt;
  detail::KeyRecorder* rec = detail::KeyRecorder::active();
  if (detail::KeySchema* shared = definition.empty() ? nullptr : rec->definition(definition)) {
    // Every position holding one of these refers to one definition: nested ones included.
    s->ref = definition;
    s = shared;
  }
  s->types.insert("map");
  for (const auto& n : names)
    if (std::find(s->oneKey.begin(), s->oneKey.end(), n) == s->oneKey.end()) s->oneKey.push_back(n);
  detail::KeyRecorder* r = detail::KeyRecorder::active();
  if (!r->isPlaceholder(node.node())) return std::nullopt;  // a real map is read as it is
  const std::optional<size_t> pick = r->chooseAlternative(names.size());
  if (!pick) return std::nullopt;
  // A key node naming the alternative, and a placeholder value bound to its property.
  YAML::Node value = r->placeholder();
  r->bind(value, s->property(names[*pick]));
  YAML::Node key(names[*pick]);
  return std::make_pair(YNode(node.fileHandle(), key), YNode(node.fileHandle(), value));
}

std::optional<std::pair<YNode, YNode>> describeEntry(const YNode& map, std::string_view help) {
  detail::KeySchema* s = describing(map.node());
  if (!s) return std::nullopt;
  s->dataKeys = true;
  detail::KeySchema& entry = s->entry();
  if (entry.help.empty()) entry.help = help;
  detail::KeyRecorder* r = detail::KeyRecorder::active();
  if (!r->isPlaceholder(map.node())) return std::nullopt;  // a real map is read as it is
  YAML::Node value = r->placeholder();
  r->bind(value, entry);
  return std::make_pair(YNode(map.fileHandle(), YAML::Node("NAME")), YNode(map.fileHandle(), value));
}

void describeValue(const YNode& node, std::optional<double> above, const std::vector<std::string>& words) {
  if (detail::KeySchema* s = describing(node.node())) {
    if (above) s->above = s->above ? std::min(*s->above, *above) : *above;
    for (const auto& w : words)
      if (std::find(s->words.begin(), s->words.end(), w) == s->words.end()) s->words.push_back(w);
  }
}

void describeHelp(const YNode& value, std::string_view help) {
  if (detail::KeySchema* s = describing(value.node()))
    if (s->help.empty()) s->help = help;
}

std::string_view helpIn(const HelpTable& table, std::string_view name) {
  auto it = table.find(name);
  return it == table.end() ? std::string_view() : it->second;
}

std::optional<std::pair<YNode, YNode>> singleKey(const YNode& node, DiagnosticList& diags, const std::string& what,
                                                 const std::vector<std::string>& names) {
  std::string definition;
  for (char c : what) definition += c == ' ' ? '_' : c;
  if (auto described = describeOneKey(node, names, definition)) return described;
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  if (!node.isMap() || node.pairs().size() != 1) {
    node.error(diags, what + " must be a map with one key, one of: " + list);
    return std::nullopt;
  }
  auto pair = node.pairs()[0];
  const std::string k = pair.first.scalar();
  if (std::find(names.begin(), names.end(), k) == names.end()) {
    pair.first.error(diags, "unknown " + what + " " + sprig::quoted(k) + didYouMean(k, names) + " (one of: " + list + ")");
    return std::nullopt;
  }
  return pair;
}

}  // namespace sprig
