#include "core/polymesh.h"

#include "core/atomic_file.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>

#include "core/paths.h"
#include "core/srgb.h"
#include "core/text.h"

namespace sprig {

namespace fs = std::filesystem;

Box3 PolyMesh::bounds() const {
  Box3 b;
  for (const auto& p : positions) b.extend(p);
  return b;
}

void reverseWinding(PolyMesh& mesh) {
  size_t first = 0;
  for (uint32_t n : mesh.faceSizes) {
    if (first + n > mesh.faceVertices.size()) break;
    std::reverse(mesh.faceVertices.begin() + std::ptrdiff_t(first) + 1, mesh.faceVertices.begin() + std::ptrdiff_t(first + n));
    first += n;
  }
}

namespace {

// Thrown inside a reader to stop at an error it cannot read past (or at too many errors);
// the errors collected so far are then thrown as one InputError.
struct StopParsing {};

// A whitespace-separated word of a line and its 1-based column.
struct Token {
  std::string_view text;
  int col = 0;
};

// Where a diagnostic points: line:col and the line's text for the caret.
struct Where {
  int line = 0;
  int col = 0;
  std::string_view lineText;
};

// Collects a reader's errors, at most kMaxPolyMeshErrors.
class Errors {
 public:
  explicit Errors(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }
  SourceLoc loc(int line, int col) const { return SourceLoc{file_, line, col}; }

  // An error at w (line 0: the file only, as in a binary PLY body).
  void at(const Where& w, std::string message) {
    if (list_.items().size() + 1 >= kMaxPolyMeshErrors) {
      list_.error(loc(w.line, w.col), "too many errors (" + std::to_string(kMaxPolyMeshErrors) + "); stopping");
      throw StopParsing{};
    }
    // Very long lines are not echoed under the message.
    std::string text = w.lineText.size() <= 200 ? std::string(w.lineText) : std::string();
    list_.error(loc(w.line, w.col), std::move(message), std::move(text));
  }
  // An error at w, then stop reading.
  [[noreturn]] void fatal(const Where& w, std::string message) {
    at(w, std::move(message));
    throw StopParsing{};
  }
  bool any() const { return list_.hasErrors(); }
  void throwIfAny() const { list_.throwIfErrors(); }

 private:
  std::string file_;
  DiagnosticList list_;
};

// `'text'`, cut to 40 bytes (the text is known to hold no control bytes).
std::string quote(std::string_view text) {
  if (text.size() > 40) return "'" + std::string(text.substr(0, 40)) + "...'";
  return "'" + std::string(text) + "'";
}


// Line and column (1-based) of byte offset pos in text.
Where whereOffset(std::string_view text, size_t pos) {
  Where w;
  size_t lineStart = 0;
  w.line = 1;
  for (size_t i = 0; i < pos; ++i)
    if (text[i] == '\n') ++w.line, lineStart = i + 1;
  w.col = int(pos - lineStart) + 1;
  return w;
}

// Fails with one error when text [0, end) is not UTF-8 text (binary data): core/text.h.
void requireText(std::string_view text, size_t end, const char* what, Errors& e) {
  if (auto fault = findNonText(text.substr(0, end))) e.fatal(Where{fault->line, fault->col, {}}, nonTextMessage(*fault, what));
}

// Lines of a text, numbered from 1, without their line endings.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text, size_t start = 0) : text_(text), pos_(start) {}
  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    size_t end = text_.find('\n', pos_);
    size_t stop = end == std::string_view::npos ? text_.size() : end;
    line = text_.substr(pos_, stop - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = end == std::string_view::npos ? text_.size() : end + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }
  size_t offset() const { return pos_; }
  // Where the text ends (for "the file ends after ...").
  Where endWhere() const { return whereOffset(text_, text_.size()); }

 private:
  std::string_view text_;
  size_t pos_ = 0;
  int number_ = 0;
};

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// Splits line into tokens; with hashComments, '#' starts a comment to the end of the line.
void splitTokens(std::string_view line, std::vector<Token>& out, bool hashComments) {
  out.clear();
  size_t i = 0;
  while (i < line.size()) {
    if (isSpace(line[i])) { ++i; continue; }
    if (hashComments && line[i] == '#') break;
    size_t j = i;
    while (j < line.size() && !isSpace(line[j]) && !(hashComments && line[j] == '#')) ++j;
    out.push_back({line.substr(i, j - i), int(i) + 1});
    i = j;
  }
}

// A token as a whole integer (optional sign).
std::optional<int64_t> toInteger(std::string_view t) {
  if (!t.empty() && t[0] == '+') t.remove_prefix(1);
  int64_t v = 0;
  auto res = std::from_chars(t.data(), t.data() + t.size(), v);
  if (t.empty() || res.ec != std::errc() || res.ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

// A token as a finite real number, else the reason it is not one.
std::optional<double> toReal(std::string_view t, std::string& why) {
  std::string_view s = !t.empty() && t[0] == '+' ? t.substr(1) : t;
  double v = 0;
  auto res = std::from_chars(s.data(), s.data() + s.size(), v, std::chars_format::general);
  bool whole = !s.empty() && res.ptr == s.data() + s.size();
  if (whole && res.ec == std::errc() && std::isfinite(v)) return v;
  why = whole || res.ec == std::errc::result_out_of_range ? quote(t) + " is not a finite number"
                                                          : "expected a number, found " + quote(t);
  return std::nullopt;
}

// A finite double as a float, else the reason.
std::optional<float> toFloat(double v, std::string_view text, std::string& why) {
  if (std::fabs(v) <= double(std::numeric_limits<float>::max())) return float(v);
  why = quote(text) + " is too large for single precision";
  return std::nullopt;
}

// A token as a finite float, else an error at its place.
std::optional<float> tokenFloat(const Token& t, const Where& line, Errors& e) {
  std::string why;
  std::optional<double> d = toReal(t.text, why);
  std::optional<float> f = d ? toFloat(*d, t.text, why) : std::nullopt;
  if (!f) e.at({line.line, t.col, line.lineText}, why);
  return f;
}

std::string limitMessage(const char* what, uint64_t count, uint64_t limit, const char* name) {
  return std::string("more than ") + std::to_string(limit) + " " + what + " (" + std::to_string(count) +
         "): the limit is PolyMeshLimits::" + name + " = " + std::to_string(limit);
}

// Accumulates a mesh's colors: every vertex has one or none.
struct ColorTracker {
  std::optional<Where> firstWith, firstWithout;
  std::string withText, withoutText;  // line texts, kept for the message
  void note(bool hasColor, const Where& w) {
    auto& first = hasColor ? firstWith : firstWithout;
    if (!first) {
      first = w;
      (hasColor ? withText : withoutText) = std::string(w.lineText);
    }
  }
  // An error when some vertices have colors and others not.
  void check(Errors& e) {
    if (!firstWith || !firstWithout) return;
    Where later = firstWith->line > firstWithout->line ? *firstWith : *firstWithout;
    Where earlier = firstWith->line > firstWithout->line ? *firstWithout : *firstWith;
    later.lineText = later.line == firstWith->line ? withText : withoutText;
    bool laterHas = later.line == firstWith->line;
    e.at(later, std::string("this vertex has ") + (laterHas ? "a color" : "no color") + " but the vertex at line " +
                    std::to_string(earlier.line) + (laterHas ? " has none" : " has one") +
                    ": give every vertex a color or none");
  }
};

// ---- Wavefront OBJ ---------------------------------------------------------------------

PolyMesh parseObj(std::string_view text, Errors& e, const PolyMeshLimits& limits) {
  PolyMesh m;
  requireText(text, text.size(), "an OBJ file", e);
  static const std::vector<std::string> kIgnored = {"vt", "vn", "o", "g", "s", "usemtl", "mtllib"};
  // Positive indices may name vertices written later; they are checked at the end.
  struct Pending {
    size_t corner;
    int64_t index;
    Where where;
    std::string lineText;
  };
  std::vector<Pending> pending;
  ColorTracker colors;
  std::vector<Token> toks;
  LineCursor lines(text);
  std::string_view line;
  while (lines.next(line)) {
    splitTokens(line, toks, true);
    if (toks.empty()) continue;
    Where w{lines.number(), toks[0].col, line};
    std::string_view kw = toks[0].text;
    if (kw == "v") {
      if (toks.size() != 4 && toks.size() != 7) {
        e.at(w, "a vertex needs x y z or x y z r g b, found " + std::to_string(toks.size() - 1) + " numbers");
        continue;
      }
      float v[6];
      bool ok = true;
      for (size_t i = 1; i < toks.size(); ++i) {
        std::optional<float> f = tokenFloat(toks[i], w, e);
        ok = ok && f;
        if (f) v[i - 1] = *f;
      }
      if (!ok) continue;
      if (m.positions.size() >= limits.maxVertices)
        e.fatal(w, limitMessage("vertices", m.positions.size() + 1, limits.maxVertices, "maxVertices"));
      m.positions.push_back({v[0], v[1], v[2]});
      colors.note(toks.size() == 7, w);
      if (toks.size() == 7) {
        for (int c = 3; c < 6; ++c)
          if (v[c] < 0 || v[c] > 1) e.at({w.line, toks[c + 1].col, line}, "color " + quote(toks[c + 1].text) + " is outside [0, 1]");
        m.colors.push_back({srgbToLinear(v[3]), srgbToLinear(v[4]), srgbToLinear(v[5])});
      }
    } else if (kw == "f") {
      if (toks.size() < 4) {
        e.at(w, "a face needs at least 3 vertices, found " + std::to_string(toks.size() - 1));
        continue;
      }
      size_t first = m.faceVertices.size();
      bool ok = true;
      for (size_t i = 1; i < toks.size(); ++i) {
        const Token& t = toks[i];
        Where tw{w.line, t.col, line};
        // v, v/vt, v//vn or v/vt/vn: only v is used; vt and vn must be integers when given.
        std::string_view parts[3];
        size_t nParts = 0, start = 0;
        bool form = true;
        for (size_t k = 0; k <= t.text.size(); ++k)
          if (k == t.text.size() || t.text[k] == '/') {
            if (nParts == 3) { form = false; break; }
            parts[nParts++] = t.text.substr(start, k - start);
            start = k + 1;
          }
        bool vtOk = nParts < 2 || (parts[1].empty() ? nParts == 3 : bool(toInteger(parts[1])));
        bool vnOk = nParts < 3 || bool(toInteger(parts[2]));
        form = form && toInteger(parts[0]) && vtOk && vnOk;
        if (!form) {
          e.at(tw, "expected a face corner v, v/vt, v//vn or v/vt/vn, found " + quote(t.text));
          ok = false;
          continue;
        }
        int64_t idx = *toInteger(parts[0]);
        int64_t have = int64_t(m.positions.size());
        if (idx == 0) {
          e.at(tw, "vertex index 0: OBJ indices start at 1 (or count back from -1)");
          ok = false;
        } else if (idx < 0 && have + idx < 0) {
          e.at(tw, "vertex index " + std::to_string(idx) + " reaches before the first vertex (" + std::to_string(have) +
                       " vertices so far)");
          ok = false;
        } else if (idx < 0) {
          m.faceVertices.push_back(uint32_t(have + idx));
        } else {
          if (idx > have) pending.push_back({m.faceVertices.size(), idx, tw, std::string(line)});
          m.faceVertices.push_back(idx - 1 <= int64_t(UINT32_MAX) ? uint32_t(idx - 1) : UINT32_MAX);
        }
      }
      if (!ok) {
        while (!pending.empty() && pending.back().corner >= first) pending.pop_back();
        m.faceVertices.resize(first);
        continue;
      }
      if (m.faceSizes.size() >= limits.maxFaces)
        e.fatal(w, limitMessage("faces", m.faceSizes.size() + 1, limits.maxFaces, "maxFaces"));
      m.faceSizes.push_back(uint32_t(toks.size() - 1));
      m.faceLocs.push_back(e.loc(w.line, w.col));
    } else if (std::find(kIgnored.begin(), kIgnored.end(), kw) == kIgnored.end()) {
      std::vector<std::string> known = kIgnored;
      known.insert(known.end(), {"v", "f"});
      e.at(w, "unknown OBJ record " + quote(kw) + didYouMean(kw, known) +
                  ": Sprig reads v and f and ignores vt, vn, o, g, s, usemtl and mtllib");
    }
  }
  for (const Pending& p : pending)
    if (uint64_t(p.index) > m.positions.size()) {
      Where pw = p.where;
      pw.lineText = p.lineText;
      e.at(pw, "vertex index " + std::to_string(p.index) + " is out of range: the file has " +
                   std::to_string(m.positions.size()) + " vertices");
    }
  colors.check(e);
  if (!colors.firstWith) m.colors.clear();
  return m;
}

// ---- PLY ---------------------------------------------------------------------------------

enum class PlyType : uint8_t { Int8, Uint8, Int16, Uint16, Int32, Uint32, Float32, Float64 };

std::optional<PlyType> plyType(std::string_view name) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::Int8},    {"int8", PlyType::Int8},     {"uchar", PlyType::Uint8},    {"uint8", PlyType::Uint8},
      {"short", PlyType::Int16},  {"int16", PlyType::Int16},   {"ushort", PlyType::Uint16},  {"uint16", PlyType::Uint16},
      {"int", PlyType::Int32},    {"int32", PlyType::Int32},   {"uint", PlyType::Uint32},    {"uint32", PlyType::Uint32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64}, {"float64", PlyType::Float64}};
  for (const auto& [n, t] : kNames)
    if (name == n) return t;
  return std::nullopt;
}

size_t plySize(PlyType t) {
  static constexpr size_t kSizes[] = {1, 1, 2, 2, 4, 4, 4, 8};
  return kSizes[size_t(t)];
}

bool plyInteger(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

// The range of an integer type, for ASCII values.
std::pair<int64_t, int64_t> plyRange(PlyType t) {
  switch (t) {
    case PlyType::Int8: return {INT8_MIN, INT8_MAX};
    case PlyType::Uint8: return {0, UINT8_MAX};
    case PlyType::Int16: return {INT16_MIN, INT16_MAX};
    case PlyType::Uint16: return {0, UINT16_MAX};
    case PlyType::Int32: return {INT32_MIN, INT32_MAX};
    default: return {0, UINT32_MAX};
  }
}

// What a vertex or face property means to the mesh.
enum class PlyRole : uint8_t { Skip, X, Y, Z, Red, Green, Blue, FaceIndices };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool list = false;
  PlyType countType = PlyType::Uint8;
  PlyRole role = PlyRole::Skip;
  Where where;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> props;
  Where where;
};

enum class PlyEncoding { Ascii, BinaryLittle, BinaryBig };

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  size_t bodyOffset = 0;
  int bodyLine = 0;  // the line the body starts on (ASCII)
  uint64_t vertexCount = 0;
  bool colorIsByte = false;
  bool hasColor = false;
};

// Reads the values of a binary PLY body.
class BinaryCursor {
 public:
  BinaryCursor(std::string_view bytes, size_t offset, bool bigEndian) : bytes_(bytes), pos_(offset), big_(bigEndian) {}
  // One value of type t; false when the data ends first.
  bool read(PlyType t, double& out) {
    size_t n = plySize(t);
    if (bytes_.size() - pos_ < n) return false;
    const char* p = bytes_.data() + pos_;
    pos_ += n;
    switch (t) {
      case PlyType::Int8: out = load<int8_t>(p); break;
      case PlyType::Uint8: out = load<uint8_t>(p); break;
      case PlyType::Int16: out = load<int16_t>(p); break;
      case PlyType::Uint16: out = load<uint16_t>(p); break;
      case PlyType::Int32: out = load<int32_t>(p); break;
      case PlyType::Uint32: out = load<uint32_t>(p); break;
      case PlyType::Float32: out = load<float>(p); break;
      case PlyType::Float64: out = load<double>(p); break;
    }
    return true;
  }
  // Bytes left after the current position.
  uint64_t remaining() const { return bytes_.size() - pos_; }
  // Lines are unknown: errors name the entry and its byte offset.
  Where where() const { return {}; }
  std::string entry(const std::string& element, uint64_t i) const {
    return element + " " + std::to_string(i) + " (byte " + std::to_string(entryStart_) + "): ";
  }
  void startEntry() { entryStart_ = pos_; }
  // An error when bytes follow the last element.
  void finish(Errors& e) const {
    if (remaining() > 0)
      e.at(where(), std::to_string(remaining()) + " bytes follow the last element (byte " + std::to_string(pos_) +
                        "): the header's counts do not match the data");
  }

 private:
  // A T stored at p in the file's byte order.
  template <class T>
  T load(const char* p) const {
    char b[sizeof(T)];
    std::memcpy(b, p, sizeof(T));
    if (big_)
      for (size_t k = 0; k < sizeof(T) / 2; ++k) std::swap(b[k], b[sizeof(T) - 1 - k]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }

  std::string_view bytes_;
  size_t pos_;
  bool big_;
  size_t entryStart_ = 0;
};

// Reads the values of an ASCII PLY body, token by token.
class AsciiCursor {
 public:
  AsciiCursor(std::string_view text, size_t offset, int firstLine) : text_(text), lines_(text, offset), base_(firstLine - 1) {}
  // One value of type t; false when the text ends first. A malformed token is an error (and stops).
  bool read(PlyType t, double& out, Errors& e) {
    if (!nextToken()) return false;
    const Token& tok = toks_[next_++];
    last_ = {base_ + lines_.number(), tok.col, line_};
    if (plyInteger(t)) {
      std::optional<int64_t> v = toInteger(tok.text);
      auto [lo, hi] = plyRange(t);
      if (!v || *v < lo || *v > hi)
        e.fatal(last_, "expected an integer from " + std::to_string(lo) + " to " + std::to_string(hi) + ", found " + quote(tok.text));
      out = double(*v);
      return true;
    }
    std::string why;
    std::optional<double> v = toReal(tok.text, why);
    std::optional<float> f = v && t == PlyType::Float32 ? toFloat(*v, tok.text, why) : std::optional<float>(0.0f);
    if (!v || !f) e.fatal(last_, why);
    out = *v;
    return true;
  }
  // An upper bound on the values left (each takes a byte and a separator).
  uint64_t remaining() const { return (text_.size() - lines_.offset() + line_.size()) / 2 + 1; }
  Where where() const { return last_; }
  std::string entry(const std::string&, uint64_t) const { return {}; }
  void startEntry() {
    if (nextToken()) last_ = {base_ + lines_.number(), toks_[next_].col, line_};
  }
  // An error when a token follows the last element.
  void finish(Errors& e) {
    if (nextToken())
      e.at({base_ + lines_.number(), toks_[next_].col, line_},
           "unexpected " + quote(toks_[next_].text) + " after the last element: the header's counts do not match the data");
  }

 private:
  bool nextToken() {
    while (next_ >= toks_.size()) {
      if (!lines_.next(line_)) return false;
      splitTokens(line_, toks_, false);
      next_ = 0;
    }
    return true;
  }
  std::string_view text_;
  LineCursor lines_;
  int base_;
  std::string_view line_;
  std::vector<Token> toks_;
  size_t next_ = 0;
  Where last_;
};

/// The PLY header's lines after "ply", through end_header, into h (format, elements and
/// their properties); h.bodyOffset and h.bodyLine locate the body.
void readPlyHeaderLines(std::string_view bytes, PlyHeader& h, Errors& e) {
  static const std::vector<std::string> kKeywords = {"format", "comment", "obj_info", "element", "property", "end_header"};
  std::vector<Token> toks;
  LineCursor lines(bytes);
  std::string_view line;
  bool haveFormat = false;
  lines.next(line);  // "ply"
  while (lines.next(line)) {
    splitTokens(line, toks, false);
    if (toks.empty()) continue;
    Where w{lines.number(), toks[0].col, line};
    std::string_view kw = toks[0].text;
    auto argAt = [&](size_t i) { return Where{w.line, i < toks.size() ? toks[i].col : int(line.size()) + 1, line}; };
    if (kw == "end_header") break;
    if (kw == "comment" || kw == "obj_info") continue;
    if (kw == "format") {
      haveFormat = true;
      std::string_view enc = toks.size() > 1 ? toks[1].text : std::string_view();
      if (enc == "ascii") h.encoding = PlyEncoding::Ascii;
      else if (enc == "binary_little_endian") h.encoding = PlyEncoding::BinaryLittle;
      else if (enc == "binary_big_endian") h.encoding = PlyEncoding::BinaryBig;
      else e.fatal(argAt(1), "expected ascii, binary_little_endian or binary_big_endian after 'format'");
      if (toks.size() != 3 || (toks[2].text != "1.0" && toks[2].text != "1"))
        e.fatal(argAt(2), "expected PLY version 1.0 after the format");
    } else if (kw == "element") {
      std::optional<int64_t> count = toks.size() == 3 ? toInteger(toks[2].text) : std::nullopt;
      if (!count || *count < 0) e.fatal(argAt(2), "expected 'element NAME COUNT' with a count of zero or more");
      for (const PlyElement& el : h.elements)
        if (el.name == toks[1].text) e.fatal(argAt(1), "element " + quote(toks[1].text) + " is declared twice");
      h.elements.push_back({std::string(toks[1].text), uint64_t(*count), {}, argAt(2)});
    } else if (kw == "property") {
      if (h.elements.empty()) e.fatal(w, "a property before any element");
      PlyProperty p;
      p.where = w;
      bool list = toks.size() > 1 && toks[1].text == "list";
      size_t want = list ? 5 : 3;
      if (toks.size() != want)
        e.fatal(w, list ? "expected 'property list COUNT_TYPE INDEX_TYPE NAME'" : "expected 'property TYPE NAME'");
      for (size_t i = 1 + list; i + 1 < want; ++i)
        if (!plyType(toks[i].text)) e.fatal(argAt(i), "unknown PLY type " + quote(toks[i].text));
      p.list = list;
      p.type = *plyType(toks[want - 2].text);
      if (list) p.countType = *plyType(toks[2].text);
      if (list && !plyInteger(p.countType)) e.fatal(argAt(2), "a list count must have an integer type");
      p.name = std::string(toks[want - 1].text);
      for (const PlyProperty& q : h.elements.back().props)
        if (q.name == p.name) e.fatal(argAt(want - 1), "property " + quote(p.name) + " is declared twice");
      h.elements.back().props.push_back(std::move(p));
    } else {
      e.fatal(w, "unknown PLY header line " + quote(kw) + didYouMean(kw, kKeywords));
    }
  }
  if (!haveFormat) e.fatal({2, 1, {}}, "the PLY header has no 'format' line");
  h.bodyOffset = lines.offset();
  h.bodyLine = lines.number() + 1;

}

/// The roles of the vertex and face properties (positions, colours, face indices),
/// checked against limits.
void assignPlyRoles(PlyHeader& h, Errors& e, const PolyMeshLimits& limits) {
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (PlyElement& el : h.elements) {
    if (el.name == "vertex") {
      vertex = &el;
      int found[6] = {};
      for (PlyProperty& p : el.props) {
        static const char* kNames[] = {"x", "y", "z", "red", "green", "blue"};
        for (int k = 0; k < 6; ++k)
          if (p.name == kNames[k]) {
            if (p.list) e.fatal(p.where, "vertex property " + quote(p.name) + " must not be a list");
            if (k >= 3 && p.type != PlyType::Uint8 && p.type != PlyType::Float32 && p.type != PlyType::Float64)
              e.fatal(p.where, "color property " + quote(p.name) + " must be uchar or float");
            p.role = PlyRole(k + 1);
            found[k] = 1;
            if (k == 3) h.colorIsByte = p.type == PlyType::Uint8;
          }
      }
      if (!found[0] || !found[1] || !found[2]) e.fatal(el.where, "the vertex element needs properties x, y and z");
      int colors = found[3] + found[4] + found[5];
      if (colors != 0 && colors != 3) e.fatal(el.where, "vertex colors need all of red, green and blue");
      h.hasColor = colors == 3;
      for (const PlyProperty& p : el.props)
        if ((p.role == PlyRole::Green || p.role == PlyRole::Blue) && (p.type == PlyType::Uint8) != h.colorIsByte)
          e.fatal(p.where, "red, green and blue must have the same type");
      h.vertexCount = el.count;
      if (el.count > limits.maxVertices) e.fatal(el.where, limitMessage("vertices", el.count, limits.maxVertices, "maxVertices"));
    } else if (el.name == "face") {
      face = &el;
      for (PlyProperty& p : el.props)
        if (p.name == "vertex_indices" || p.name == "vertex_index") {
          if (!p.list || !plyInteger(p.type))
            e.fatal(p.where, "face property " + quote(p.name) + " must be a list of an integer type");
          if (face->props.end() != std::find_if(face->props.begin(), face->props.end(),
                                                [](const PlyProperty& q) { return q.role == PlyRole::FaceIndices; }))
            e.fatal(p.where, "the face element has both vertex_indices and vertex_index");
          p.role = PlyRole::FaceIndices;
        }
      if (std::none_of(el.props.begin(), el.props.end(), [](const PlyProperty& p) { return p.role == PlyRole::FaceIndices; }))
        e.fatal(el.where, "the face element needs a list property vertex_indices (or vertex_index)");
      if (el.count > limits.maxFaces) e.fatal(el.where, limitMessage("faces", el.count, limits.maxFaces, "maxFaces"));
    } else if (el.count > std::max(limits.maxVertices, limits.maxFaces)) {
      e.fatal(el.where, limitMessage(("'" + el.name + "' entries").c_str(), el.count,
                                     std::max(limits.maxVertices, limits.maxFaces), "maxFaces"));
    }
  }
  if (!vertex) e.fatal({1, 1, "ply"}, "the PLY file has no 'vertex' element");
  if (!face) e.fatal({1, 1, "ply"}, "the PLY file has no 'face' element: Sprig reads meshes, not point clouds");

}

/// Declared counts against the bytes that follow, before anything is allocated: each entry
/// takes at least its fixed-size values and list counts (binary), or a byte and a
/// separator per value (ASCII).
void checkPlyCounts(std::string_view bytes, const PlyHeader& h, Errors& e) {
  uint64_t available = bytes.size() - h.bodyOffset;
  uint64_t needed = 0;
  for (const PlyElement& el : h.elements) {
    uint64_t per = 0;
    for (const PlyProperty& p : el.props)
      per += h.encoding == PlyEncoding::Ascii ? 2 : plySize(p.list ? p.countType : p.type);
    if (per == 0) continue;
    if (el.count > (available - std::min(needed, available) + 1) / per) {
      std::string unit = h.encoding == PlyEncoding::Ascii ? " characters" : " bytes";
      e.fatal(el.where, "element " + quote(el.name) + " declares " + std::to_string(el.count) + " entries of at least " +
                            std::to_string(per) + unit + " each, but the file has " + std::to_string(available) +
                            " bytes after its header (truncated, or a wrong count?)");
    }
    needed += el.count * per;
  }
}

PlyHeader parsePlyHeader(std::string_view bytes, Errors& e, const PolyMeshLimits& limits) {
  PlyHeader h;
  if (!(bytes.substr(0, 4) == "ply\n" || bytes.substr(0, 5) == "ply\r\n"))
    e.fatal({1, 1, {}}, "not a PLY file: the first line must be 'ply'");
  size_t end = bytes.find("end_header");
  while (end != std::string_view::npos && !(bytes[end - 1] == '\n' &&
                                            (bytes.substr(end + 10, 1) == "\n" || bytes.substr(end + 10, 2) == "\r\n")))
    end = bytes.find("end_header", end + 1);
  requireText(bytes, end == std::string_view::npos ? bytes.size() : end, "a PLY header", e);
  if (end == std::string_view::npos) e.fatal({1, 1, "ply"}, "the PLY header has no 'end_header' line");

  readPlyHeaderLines(bytes, h, e);
  assignPlyRoles(h, e, limits);
  checkPlyCounts(bytes, h, e);
  return h;
}

template <class Cursor>
bool readValue(Cursor& c, PlyType t, double& v, Errors& e) {
  if constexpr (std::is_same_v<Cursor, AsciiCursor>) return c.read(t, v, e);
  else return c.read(t, v);
}

// Reads every element of a PLY body into m.
template <class Cursor>
void readPlyBody(Cursor& cur, const PlyHeader& h, PolyMesh& m, Errors& e) {
  m.positions.reserve(h.vertexCount);
  if (h.hasColor) m.colors.reserve(h.vertexCount);
  for (const PlyElement& el : h.elements) {
    bool isVertex = el.name == "vertex", isFace = el.name == "face";
    if (isFace) {
      m.faceSizes.reserve(el.count);
      m.faceLocs.reserve(el.count);
      m.faceVertices.reserve(el.count * 3);
    }
    for (uint64_t i = 0; i < el.count; ++i) {
      cur.startEntry();
      Where entryAt = cur.where();
      Vec3 pos(0), color(0);
      for (const PlyProperty& p : el.props) {
        double v = 0;
        auto truncated = [&] {
          e.fatal(cur.where(), cur.entry(el.name, i) + "the file ends inside " + el.name + " " + std::to_string(i) +
                                   " of " + std::to_string(el.count) + " (truncated?)");
        };
        if (p.list) {
          if (!readValue(cur, p.countType, v, e)) truncated();
          Where at = cur.where();
          if (v < 0) e.fatal(at, cur.entry(el.name, i) + "bad list count " + std::to_string(int64_t(v)) + " for " + quote(p.name));
          auto count = uint64_t(v);
          uint64_t unit = std::is_same_v<Cursor, AsciiCursor> ? 1 : plySize(p.type);
          if (count > cur.remaining() / unit)
            e.fatal(at, cur.entry(el.name, i) + "list count " + std::to_string(count) + " for " + quote(p.name) +
                            " needs more data than the file holds (truncated?)");
          bool faceList = isFace && p.role == PlyRole::FaceIndices;
          if (faceList && count < 3)
            e.at(at, cur.entry(el.name, i) + "a face needs at least 3 vertices, found " + std::to_string(count));
          bool ok = count >= 3;
          size_t first = m.faceVertices.size();
          for (uint64_t k = 0; k < count; ++k) {
            if (!readValue(cur, p.type, v, e)) truncated();
            if (!std::isfinite(v)) e.at(cur.where(), cur.entry(el.name, i) + quote(p.name) + " holds a value that is not a finite number");
            if (!faceList) continue;
            if (v < 0 || v >= double(h.vertexCount)) {
              e.at(cur.where(), cur.entry(el.name, i) + "vertex index " + std::to_string(int64_t(v)) +
                                    " is out of range: the file has " + std::to_string(h.vertexCount) + " vertices");
              ok = false;
            }
            if (ok) m.faceVertices.push_back(uint32_t(v));
          }
          if (faceList && ok) {
            m.faceSizes.push_back(uint32_t(count));
            m.faceLocs.push_back(e.loc(entryAt.line, entryAt.col));
          } else if (faceList) {
            m.faceVertices.resize(first);
          }
          continue;
        }
        if (!readValue(cur, p.type, v, e)) truncated();
        if (!std::isfinite(v) || std::fabs(v) > double(std::numeric_limits<float>::max())) {
          e.at(cur.where(), cur.entry(el.name, i) + "property " + quote(p.name) + " is not a finite number");
          continue;
        }
        if (!isVertex || p.role == PlyRole::Skip) continue;
        if (p.role <= PlyRole::Z) {
          pos[int(p.role) - int(PlyRole::X)] = float(v);
        } else {
          if (!h.colorIsByte && (v < 0 || v > 1))
            e.at(cur.where(), cur.entry(el.name, i) + "color " + quote(p.name) + " is outside [0, 1]");
          color[int(p.role) - int(PlyRole::Red)] = h.colorIsByte ? srgbToLinear(float(v) / 255.0f) : float(v);
        }
      }
      if (isVertex) {
        m.positions.push_back(pos);
        if (h.hasColor) m.colors.push_back(color);
      }
    }
  }
  cur.finish(e);
}

PolyMesh parsePly(std::string_view bytes, Errors& e, const PolyMeshLimits& limits) {
  PolyMesh m;
  PlyHeader h = parsePlyHeader(bytes, e, limits);
  if (h.encoding == PlyEncoding::Ascii) {
    requireText(bytes, bytes.size(), "an ASCII PLY file", e);
    AsciiCursor cur(bytes, h.bodyOffset, h.bodyLine);
    readPlyBody(cur, h, m, e);
  } else {
    BinaryCursor cur(bytes, h.bodyOffset, h.encoding == PlyEncoding::BinaryBig);
    readPlyBody(cur, h, m, e);
  }
  return m;
}

// ---- OFF ---------------------------------------------------------------------------------

// Reads the next line that holds tokens (comments and blank lines skipped).
bool nextTokens(LineCursor& lines, std::string_view& line, std::vector<Token>& toks) {
  while (lines.next(line)) {
    splitTokens(line, toks, true);
    if (!toks.empty()) return true;
  }
  return false;
}

PolyMesh parseOff(std::string_view text, Errors& e, const PolyMeshLimits& limits) {
  PolyMesh m;
  requireText(text, text.size(), "an OFF file", e);
  LineCursor lines(text);
  std::string_view line;
  std::vector<Token> toks;
  if (!nextTokens(lines, line, toks)) e.fatal({1, 1, {}}, "not an OFF file: it is empty");
  Where w{lines.number(), toks[0].col, line};
  std::string_view magic = toks[0].text;
  bool color = magic == "COFF";
  if (magic != "OFF" && !color) {
    bool variant = magic.size() > 3 && magic.substr(magic.size() - 3) == "OFF";
    e.fatal(w, variant ? "the OFF variant " + quote(magic) + " is not supported: Sprig reads OFF and COFF"
                       : "not an OFF file: the first line must be OFF or COFF, found " + quote(magic));
  }
  // The counts follow on the same line or the next.
  toks.erase(toks.begin());
  if (toks.empty() && !nextTokens(lines, line, toks)) e.fatal(lines.endWhere(), "the file ends before the counts 'vertices faces edges'");
  w = {lines.number(), toks[0].col, line};
  std::optional<int64_t> nv = toInteger(toks[0].text);
  std::optional<int64_t> nf = toks.size() > 1 ? toInteger(toks[1].text) : std::nullopt;
  if (toks.size() < 2 || toks.size() > 3 || !nv || !nf || *nv < 0 || *nf < 0 || (toks.size() == 3 && !toInteger(toks[2].text)))
    e.fatal(w, "expected the counts 'vertices faces edges' (integers, zero or more)");
  if (uint64_t(*nv) > limits.maxVertices) e.fatal(w, limitMessage("vertices", *nv, limits.maxVertices, "maxVertices"));
  if (uint64_t(*nf) > limits.maxFaces) e.fatal(w, limitMessage("faces", *nf, limits.maxFaces, "maxFaces"));
  // A vertex line takes at least 6 bytes ("0 0 0\n"), a face line 8 ("3 0 1 2\n").
  uint64_t available = text.size() - lines.offset();
  if (uint64_t(*nv) * 6 + uint64_t(*nf) * 8 > available + 1)
    e.fatal(w, "the header declares " + std::to_string(*nv) + " vertices and " + std::to_string(*nf) +
                   " faces, more than the " + std::to_string(available) + " bytes that follow can hold (truncated, or a wrong count?)");

  m.positions.reserve(size_t(*nv));
  if (color) m.colors.reserve(size_t(*nv));
  for (int64_t i = 0; i < *nv; ++i) {
    if (!nextTokens(lines, line, toks))
      e.fatal(lines.endWhere(), "the file ends after " + std::to_string(i) + " of " + std::to_string(*nv) + " vertices");
    w = {lines.number(), toks[0].col, line};
    if (color ? toks.size() != 6 && toks.size() != 7 : toks.size() != 3) {
      e.at(w, std::string(color ? "a COFF vertex needs x y z r g b [a]" : "an OFF vertex needs x y z") + ", found " +
                  std::to_string(toks.size()) + " numbers");
      m.positions.push_back(Vec3(0));
      if (color) m.colors.push_back(Vec3(0));
      continue;
    }
    float v[7] = {};
    for (size_t k = 0; k < toks.size(); ++k)
      if (std::optional<float> f = tokenFloat(toks[k], w, e)) v[k] = *f;
    m.positions.push_back({v[0], v[1], v[2]});
    if (!color) continue;
    // Integers 0-255, or floats in [0, 1]; both sRGB-encoded.
    bool bytes = std::all_of(toks.begin() + 3, toks.end(), [](const Token& t) { return bool(toInteger(t.text)); });
    float scale = bytes ? 255.0f : 1.0f;
    for (size_t k = 3; k < toks.size(); ++k)
      if (v[k] < 0 || v[k] > scale)
        e.at({w.line, toks[k].col, line}, "color " + quote(toks[k].text) + (bytes ? " is outside 0-255" : " is outside [0, 1]"));
    m.colors.push_back({srgbToLinear(v[3] / scale), srgbToLinear(v[4] / scale), srgbToLinear(v[5] / scale)});
  }

  m.faceSizes.reserve(size_t(*nf));
  m.faceLocs.reserve(size_t(*nf));
  m.faceVertices.reserve(size_t(*nf) * 3);
  for (int64_t i = 0; i < *nf; ++i) {
    if (!nextTokens(lines, line, toks))
      e.fatal(lines.endWhere(), "the file ends after " + std::to_string(i) + " of " + std::to_string(*nf) + " faces");
    w = {lines.number(), toks[0].col, line};
    std::optional<int64_t> n = toInteger(toks[0].text);
    if (!n || *n < 3) {
      e.at(w, "a face starts with its number of vertices (3 or more), found " + quote(toks[0].text));
      continue;
    }
    // After the n indices: no color, a color-map index, RGB or RGBA.
    int64_t extra = int64_t(toks.size()) - 1 - *n;
    if (extra < 0 || extra == 2 || extra > 4) {
      e.at(w, "this face has " + std::to_string(*n) + " vertices but its line holds " + std::to_string(toks.size() - 1) +
                  " values (expected the indices and 0, 1, 3 or 4 color values)");
      continue;
    }
    size_t first = m.faceVertices.size();
    bool ok = true;
    for (int64_t k = 1; k <= *n; ++k) {
      const Token& t = toks[size_t(k)];
      std::optional<int64_t> idx = toInteger(t.text);
      if (!idx || *idx < 0 || *idx >= *nv) {
        e.at({w.line, t.col, line}, idx ? "vertex index " + std::to_string(*idx) + " is out of range: the file has " +
                                              std::to_string(*nv) + " vertices"
                                        : "expected a vertex index, found " + quote(t.text));
        ok = false;
        continue;
      }
      m.faceVertices.push_back(uint32_t(*idx));
    }
    std::string why;
    for (size_t k = size_t(*n) + 1; k < toks.size(); ++k)
      if (!toReal(toks[k].text, why)) e.at({w.line, toks[k].col, line}, why);
    if (!ok) {
      m.faceVertices.resize(first);
      continue;
    }
    m.faceSizes.push_back(uint32_t(*n));
    m.faceLocs.push_back(e.loc(w.line, w.col));
  }
  if (nextTokens(lines, line, toks))
    e.at({lines.number(), toks[0].col, line}, "unexpected " + quote(toks[0].text) + " after the last face: the header's counts do not match the data");
  return m;
}

}  // namespace

MeshFileFormat meshFileFormatFor(const fs::path& path) {
  std::string ext = lowerExtension(path);
  if (ext == ".obj") return MeshFileFormat::Obj;
  if (ext == ".ply") return MeshFileFormat::Ply;
  if (ext == ".off") return MeshFileFormat::Off;
  throw std::invalid_argument("cannot tell the mesh format of '" + path.string() + "': use the extension .obj, .ply or .off");
}

PolyMesh parsePolyMesh(std::string_view bytes, MeshFileFormat format, std::string displayPath, const PolyMeshLimits& limits) {
  Errors e(std::move(displayPath));
  PolyMesh m;
  try {
    if (bytes.size() > limits.maxFileBytes)
      e.fatal({}, "the file has " + std::to_string(bytes.size()) + " bytes, more than the limit of " +
                      std::to_string(limits.maxFileBytes) + " bytes (PolyMeshLimits::maxFileBytes)");
    if (bytes.substr(0, 3) == "\xEF\xBB\xBF" && format != MeshFileFormat::Ply) bytes.remove_prefix(3);
    switch (format) {
      case MeshFileFormat::Obj: m = parseObj(bytes, e, limits); break;
      case MeshFileFormat::Ply: m = parsePly(bytes, e, limits); break;
      case MeshFileFormat::Off: m = parseOff(bytes, e, limits); break;
    }
  } catch (const StopParsing&) {
  }
  e.throwIfAny();
  return m;
}

PolyMesh readPolyMesh(const fs::path& path, std::string displayPath, const PolyMeshLimits& limits) {
  MeshFileFormat format = meshFileFormatFor(path);
  if (displayPath.empty()) displayPath = path.string();
  std::string bytes = readInputFile(path, displayPath, limits.maxFileBytes, "PolyMeshLimits::maxFileBytes");
  return parsePolyMesh(bytes, format, std::move(displayPath), limits);
}

Mesh triangulate(const PolyMesh& poly) {
  Mesh m;
  m.positions = poly.positions;
  if (poly.colors.size() == poly.positions.size()) m.colors = poly.colors;
  m.triangles.reserve(poly.cornerCount() - 2 * std::min(poly.cornerCount() / 3, poly.faceCount()));
  size_t corner = 0;
  for (uint32_t n : poly.faceSizes) {
    const uint32_t* v = poly.faceVertices.data() + corner;
    for (uint32_t k = 1; k + 1 < n; ++k) m.triangles.push_back({v[0], v[k], v[k + 1]});
    corner += n;
  }
  return m;
}

PolyMesh toPolyMesh(const Mesh& mesh) {
  PolyMesh p;
  p.positions = mesh.positions;
  if (mesh.colors.size() == mesh.positions.size()) p.colors = mesh.colors;
  p.faceSizes.assign(mesh.triangles.size(), 3);
  p.faceVertices.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) p.faceVertices.insert(p.faceVertices.end(), {t.x, t.y, t.z});
  return p;
}

PolyTopology checkPolyMesh(const PolyMesh& mesh, DiagnosticList& diags) {
  PolyTopology topo;
  auto locOf = [&](size_t f) { return f < mesh.faceLocs.size() ? mesh.faceLocs[f] : SourceLoc{}; };
  // "face N: " when the location has no line to point at.
  auto prefix = [&](size_t f) { return locOf(f).line > 0 ? std::string() : "face " + std::to_string(f) + ": "; };
  auto placeOf = [&](size_t f) {
    SourceLoc l = locOf(f);
    return l.line > 0 ? "line " + std::to_string(l.line) : "face " + std::to_string(f);
  };

  // Each directed edge (a,b) of a valid face: key min<<32|max, its face and direction.
  struct Edge {
    uint64_t key;
    uint32_t face;
    bool forward;  // a < b
    bool operator<(const Edge& o) const { return key != o.key ? key < o.key : face < o.face; }
  };
  std::vector<Edge> edges;
  edges.reserve(mesh.cornerCount());
  size_t n = mesh.positions.size(), corner = 0;
  std::vector<uint32_t> sorted;
  for (size_t f = 0; f < mesh.faceCount(); ++f) {
    uint32_t size = mesh.faceSizes[f];
    if (corner + size > mesh.cornerCount()) {
      diags.error(locOf(f), prefix(f) + "the face lists run past the end of faceVertices");
      break;
    }
    const uint32_t* v = mesh.faceVertices.data() + corner;
    corner += size;
    if (size < 3) {
      diags.error(locOf(f), prefix(f) + "a face needs at least 3 vertices, found " + std::to_string(size));
      continue;
    }
    const uint32_t* bad = std::find_if(v, v + size, [&](uint32_t i) { return i >= n; });
    if (bad != v + size) {
      diags.error(locOf(f), prefix(f) + "vertex index " + std::to_string(*bad) + " is out of range (" + std::to_string(n) + " vertices)");
      continue;
    }
    sorted.assign(v, v + size);
    std::sort(sorted.begin(), sorted.end());
    auto rep = std::adjacent_find(sorted.begin(), sorted.end());
    if (rep != sorted.end()) {
      diags.error(locOf(f), prefix(f) + "the face repeats vertex " + std::to_string(*rep) + " (0-based)");
      continue;
    }
    for (uint32_t k = 0; k < size; ++k) {
      uint32_t a = v[k], b = v[(k + 1) % size];
      edges.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), uint32_t(f), a < b});
    }
  }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j].key == edges[i].key) ++j;
    auto a = uint32_t(edges[i].key >> 32), b = uint32_t(edges[i].key);
    std::string edge = "the edge between vertices " + std::to_string(a) + " and " + std::to_string(b) + " (0-based)";
    if (j - i == 1) {
      ++topo.boundaryEdges;
    } else if (j - i > 2) {
      ++topo.nonManifoldEdges;
      size_t f = edges[i + 2].face;
      diags.error(locOf(f), prefix(f) + "this face is the third on " + edge + " (the others are at " + placeOf(edges[i].face) +
                                " and " + placeOf(edges[i + 1].face) + "): a base mesh must be manifold");
    } else if (edges[i].forward == edges[i + 1].forward) {
      ++topo.inconsistentEdges;
      size_t f = edges[i + 1].face;
      diags.error(locOf(f), prefix(f) + "this face runs along " + edge + " in the same direction as the face at " +
                                placeOf(edges[i].face) + ": one of them is flipped (faces must be counter-clockwise seen from outside)");
    }
    i = j;
  }
  return topo;
}

}  // namespace sprig
