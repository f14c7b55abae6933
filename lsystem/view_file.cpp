#include "lsystem/view_file.h"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <cctype>
#include <cmath>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>

#include "core/atomic_file.h"
#include "core/srgb.h"
#include "core/text.h"

namespace sprig::lsystem {

namespace {

/// Keys that only change how cpfg's window shows the model: read and ignored, with a warning.
const char* const kViewerKeys[] = {
    "viewpoint",          "view reference point", "twist",          "projection",
    "front distance",     "back distance",        "scale factor",   "z buffer",
    "cue range",          "shade mode",           "light direction", "diffuse reflection",
    "surface ambient",    "surface diffuse",      "box",            "background color",
    "ambient light",      "winfont",        "polygonization level",
    "light",              "render mode",          "tapered lines",
    "viewing angle",      "interpretation step", "environment display",
    "antialiasing",       "min zoom",             "max zoom",       "generate on view change",
    "concave polygons",   "shadow map",           "PS linecap",     "rayshade objects",
    "rayshade scale",
};

/// Keys naming files whose uses (`~`, `func`, `curveX`, `@#`, `inblob`) are errors in the
/// grammar: not read, with a warning.
const char* const kFileKeys[] = {"tsurface", "blob"};

/// Most `surface:` lines of a view file (cpfg's SURFACES - 1).
constexpr size_t kMaxSurfaces = 14;

const char* const kReadKeys[] = {
    "angle factor",  "angle increment",   "initial color", "color increment", "initial line width",
    "line width increment", "line style", "initial scale", "scale multiplier", "tropism", "torque",
    "tropism direction", "initial elasticity", "elasticity increment", "function", "function set", "surface", "line", "background scene", "curve", "contour", "contour sides",
    "texture",
};

/// The view file's text with `/* */` and `//` comments blanked (newlines kept, so positions
/// hold): cpfg runs its view file through the C preprocessor, which removes both.
std::string blankComments(std::string s, int& openLine) {
  openLine = 0;
  int line = 1;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '\n') ++line;
    if (s[i] == '/' && i + 1 < s.size() && s[i + 1] == '/') {
      while (i < s.size() && s[i] != '\n') s[i++] = ' ';
      if (i < s.size()) ++line;
      continue;
    }
    if (s[i] == '/' && i + 1 < s.size() && s[i + 1] == '*') {
      const int start = line;
      size_t j = i + 2;
      while (j + 1 < s.size() && !(s[j] == '*' && s[j + 1] == '/')) ++j;
      const bool closed = j + 1 < s.size();
      const size_t end = closed ? j + 2 : s.size();
      for (size_t k = i; k < end; ++k)
        if (s[k] != '\n') s[k] = ' ';
        else ++line;
      if (!closed) openLine = start;
      i = end - 1;
      if (i < s.size() && s[i] == '\n') --line;  // counted by the loop
    }
  }
  return s;
}

/// The numbers of text, separated by spaces, tabs or commas; nullopt when a word is no number.
std::optional<std::vector<double>> numbers(const std::string& text) {
  std::vector<double> out;
  std::string word;
  std::istringstream in(text);
  std::string all;
  for (char c : text) all += c == ',' ? ' ' : c;
  std::istringstream words(all);
  while (words >> word) {
    auto v = parseFiniteNumber(word);
    if (!v) return std::nullopt;
    out.push_back(*v);
  }
  return out;
}

class ViewParser {
 public:
  explicit ViewParser(const std::string& fileName) { view_.file = fileName; }

  ViewFile run(const std::string& text) {
    int openLine = 0;
    const std::string clean = blankComments(text, openLine);
    if (openLine) diags_.error(SourceLoc{view_.file, openLine, 1}, "unterminated comment '/*'", lineOf(text, openLine));
    const std::vector<std::string> raws = lines(text), cleans = lines(clean);
    for (size_t k = 0; k < cleans.size(); ++k) {
      raw_ = k < raws.size() ? raws[k] : std::string();
      readLine(static_cast<int>(k) + 1, cleans[k]);
    }
    // A surface's texture number names a `texture:` line, which may come after it.
    for (const SurfaceTexture& st : surfaceTextures_)
      if (static_cast<size_t>(st.texture) > view_.textures.size()) {
        raw_ = st.raw;
        error(st.line, st.col, "the surface's texture " + std::to_string(st.texture) + " names no texture: the view file has " +
                                   std::to_string(view_.textures.size()) + " 'texture:' line" + (view_.textures.size() == 1 ? "" : "s"));
      }
    checkBackgroundTubes();
    diags_.throwIfErrors();
    if (!viewerKeys_.empty()) {
      raw_ = viewerRaw_;
      warn(viewerLine_, 0, "ignored, as they set how cpfg's window shows the model, not its geometry: " + viewerKeys_);
    }
    view_.warnings = warnings_;
    if (warningsNotKept_ > 0) {
      Diagnostic d;
      d.severity = Severity::Note;
      d.loc = SourceLoc{view_.file};
      d.message = std::to_string(warningsNotKept_) + " more warning" + (warningsNotKept_ == 1 ? "" : "s") + " not shown (at most " +
                  std::to_string(kMaxDiagnostics) + " are; kMaxDiagnostics)";
      view_.warnings.push_back(std::move(d));
    }
    return view_;
  }

 private:
  /// text cut at its newlines, without a trailing `\r`.
  static std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string l; std::getline(in, l);) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      out.push_back(std::move(l));
    }
    return out;
  }

  static std::string lineOf(const std::string& text, int line) {
    std::istringstream in(text);
    std::string l;
    for (int k = 0; k < line && std::getline(in, l); ++k) {}
    if (!l.empty() && l.back() == '\r') l.pop_back();
    return l;
  }

  void error(int line, size_t col0, const std::string& msg) {
    diags_.error(SourceLoc{view_.file, line, static_cast<int>(col0) + 1}, msg, raw_);
  }
  void warn(int line, size_t col0, const std::string& msg) {
    if (warnings_.size() >= kMaxDiagnostics) {
      ++warningsNotKept_;
      return;
    }
    Diagnostic d;
    d.severity = Severity::Warning;
    d.loc = SourceLoc{view_.file, line, static_cast<int>(col0) + 1};
    d.message = msg;
    d.sourceLine = raw_;
    warnings_.push_back(std::move(d));
  }

  /// The numbers of value (at column col0 of line), exactly `min..max` of them, else an error.
  std::optional<std::vector<double>> values(int line, size_t col0, const std::string& key, const std::string& value,
                                            size_t min, size_t max) {
    auto v = numbers(value);
    if (!v || v->size() < min || v->size() > max) {
      std::string want = min == max ? std::to_string(min) : std::to_string(min) + " to " + std::to_string(max);
      error(line, col0, "'" + key + ":' expects " + want + (max == 1 ? " number" : " numbers") + ", got '" + trimmed(value) + "'");
      return std::nullopt;
    }
    return v;
  }

  static std::string formatLimit(double v) { return std::to_string(static_cast<long>(v)); }

  static std::string trimmed(const std::string& s) {
    size_t b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return {};
    size_t e = s.find_last_not_of(" \t");
    return s.substr(b, e + 1 - b);
  }

  void readLine(int line, const std::string& s) {
    const size_t b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return;
    if (s[b] == '#') {
      size_t e = b + 1;
      while (e < s.size() && std::isalpha(static_cast<unsigned char>(s[e]))) ++e;
      error(line, b, "C preprocessor directive '" + s.substr(b, e - b) + "' in a view file is not supported");
      return;
    }
    const size_t colon = s.find(':', b);
    if (colon == std::string::npos) {
      error(line, b, "expected a view file command such as 'angle increment: 30'");
      return;
    }
    std::string key;
    for (size_t i = b; i < colon; ++i) {
      const char c = s[i] == '\t' ? ' ' : s[i];
      if (c == ' ' && (key.empty() || key.back() == ' ')) continue;
      key += c;
    }
    while (!key.empty() && key.back() == ' ') key.pop_back();
    const std::string value = s.substr(colon + 1);
    const size_t vcol = colon + 1 + std::min(value.size(), value.find_first_not_of(" \t") == std::string::npos
                                                                  ? value.size()
                                                                  : value.find_first_not_of(" \t"));
    readKey(line, b, vcol, key, value);
  }

  void readKey(int line, size_t kcol, size_t vcol, const std::string& key, const std::string& value) {
    auto is = [&](const char* k) { return key == k; };
    if (is("angle increment") || is("angle factor")) {
      if (trimmed(value) == "?") {
        // vlab's exercises leave '?' for the student to fill in. cpfg (interpret.c) warns of
        // invalid parameters and its fscanf leaves the angle in effect (45 degrees unless set):
        // 'angle increment: ?' keeps it, 'angle factor: ?' still divides 360 by it.
        warn(line, vcol, "'" + key + ": ?' has no number: as cpfg, the angle in effect is " +
                             (is("angle factor") ? "the factor (the angle becomes 360 / it)" : "kept"));
        const double current = view_.angleDeg.value_or(kCpfgDefaultAngleDeg);
        if (is("angle factor") && current != 0) view_.angleDeg = 360.0 / current;
        return;
      }
      if (auto v = values(line, vcol, key, value, 1, 1)) {
        if (is("angle factor") && (*v)[0] == 0) error(line, vcol, "'angle factor:' must not be 0 (the angle is 360 / factor)");
        else view_.angleDeg = is("angle factor") ? 360.0 / (*v)[0] : (*v)[0];
      }
    } else if (is("initial color") || is("color increment")) {
      if (auto v = values(line, vcol, key, value, 1, 2)) {
        const double limit = is("initial color") ? 65535 : 255;
        if (std::fabs((*v)[0]) > limit)
          error(line, vcol, "'" + key + ":' must be from " + formatLimit(-limit) + " to " + formatLimit(limit));
        else
          (is("initial color") ? view_.initialColor : view_.colorIncrement) = static_cast<int>((*v)[0]);
      }
    } else if (is("initial line width")) {
      // cpfg: a number, then an optional style word (`p`ixels, `s`haded cylinders); a number
      // alone means polygons in world units.
      std::istringstream in(value);
      std::string number, style;
      in >> number >> style;
      auto w = parseFiniteNumber(number);
      if (!w) {
        error(line, vcol, "'initial line width:' expects a number, got '" + trimmed(value) + "'");
        return;
      }
      view_.lineWidth = *w;
      view_.lineStyle = style.empty() ? CpfgLineStyle::Polygon
                        : style[0] == 'p' ? CpfgLineStyle::Pixel
                        : style[0] == 's' ? CpfgLineStyle::Cylinder
                                          : CpfgLineStyle::Polygon;
    } else if (is("line width increment")) {
      if (auto v = values(line, vcol, key, value, 1, 1)) view_.widthIncrement = (*v)[0];
    } else if (is("line style")) {
      // cpfg (interpret.c, "line style:") reads one word: pixel, polygon, cylinder, or a
      // digit 1 to 3 for them; any other word leaves the style in effect (vlab's
      // Sierpinski and canalization objects write `wireframe`, a render mode).
      const std::string v = trimmed(value);
      const std::string word = v.substr(0, v.find_first_of(" \t"));
      if (word == "pixel" || word == "1") view_.lineStyle = CpfgLineStyle::Pixel;
      else if (word == "polygon" || word == "2") view_.lineStyle = CpfgLineStyle::Polygon;
      else if (word == "cylinder" || word == "3") view_.lineStyle = CpfgLineStyle::Cylinder;
      else if (word.empty() || std::isdigit(static_cast<unsigned char>(word[0])))
        error(line, vcol, "'line style:' is pixel, polygon or cylinder (or 1, 2, 3), got '" + v + "'");
      else
        warn(line, vcol, "'line style: " + word + "' is none of cpfg's line styles (pixel, polygon, cylinder): as cpfg does, the line style in effect is kept");
    } else if (is("initial scale")) {
      if (auto v = values(line, vcol, key, value, 1, 1)) view_.initialScale = (*v)[0];
    } else if (is("scale multiplier")) {
      if (auto v = values(line, vcol, key, value, 1, 1)) view_.scaleMultiplier = (*v)[0];
    } else if (is("tropism") || is("torque")) {
      readTropism(line, vcol, value, is("torque"));
    } else if (is("initial elasticity")) {
      if (auto v = values(line, vcol, key, value, 1, 1)) view_.oldElasticity = (*v)[0];
    } else if (is("elasticity increment")) {
      if (auto v = values(line, vcol, key, value, 1, 1)) view_.oldElasticityIncrement = (*v)[0];
    } else if (is("tropism direction")) {
      if (auto v = values(line, vcol, key, value, 3, 3)) {
        const DVec3 d((*v)[0], (*v)[1], (*v)[2]);
        if (glm::length(d) == 0) error(line, vcol, "'tropism direction:' must not be the zero vector");
        else view_.oldTropismDirection = glm::normalize(d);
      }
    } else if (is("function")) {
      readFunction(line, vcol, value);
      view_.functionNames.clear();  // cpfg: the functions are no longer only the set's
    } else if (is("function set")) {
      readFunctionSet(line, vcol, value);
    } else if (is("surface") || is("line")) {
      readSurface(line, vcol, value, is("line"));
    } else if (is("background scene")) {
      readBackground(line, vcol, value);
    } else if (is("texture")) {
      readTexture(line, vcol, value);
    } else if (is("curve")) {
      readCurve(line, vcol, value);
    } else if (is("contour")) {
      readContour(line, vcol, value);
    } else if (is("contour sides")) {
      if (auto v = values(line, vcol, key, value, 1, 1)) {
        if ((*v)[0] != std::floor((*v)[0]) || (*v)[0] < CpfgContour::kMinSides || (*v)[0] > CpfgContour::kMaxSides)
          error(line, vcol, "'contour sides:' is a whole number from 3 to 1024");
        else
          view_.contourSides = static_cast<int>((*v)[0]);
      }
    } else {
      readOtherKey(line, kcol, key, value);
    }
  }

  /// A key readKey does not read: one Sprig refuses when drawing, a file or viewer key
  /// cpfg's derivation ignores, or an unknown one (an error naming the nearest keys).
  void readOtherKey(int line, size_t kcol, const std::string& key, const std::string& value) {
    for (const char* k : kFileKeys)
      if (key == k) {
        if (key == "tsurface") {
          const size_t at = value.find_first_not_of(" \t");
          if (at != std::string::npos) view_.tsurfaceIds += value[at];
        }
        warn(line, kcol, "'" + key + ":' ignored: the grammar's uses of it are errors (not supported)");
        return;
      }
    if (key == "interpretation past %") {  // read: whether the turtle skips a pending cut
      view_.interpretPastCut = trimmed(value).rfind("off", 0) != 0;
      return;
    }
    if (key == "font") {  // read: the labels' font (cpfg's fscanf reads one word)
      const std::string t = trimmed(value);
      view_.font = t.substr(0, t.find_first_of(" \t"));
      return;
    }
    if (key == "twist of cylinders") {  // read: whether generalized cylinders follow the turtle's roll
      view_.twistCylinders = trimmed(value).rfind("on", 0) == 0;
      return;
    }
    if (key == "environment display") {  // read: it says when ?E modules go to the environmental program
      view_.environmentBefore = trimmed(value).rfind("before", 0) == 0;
      return;
    }
    for (const char* k : kViewerKeys)
      if (key == k) {
        if (key == "box") view_.box = true;
        if (key == "tapered lines") {  // cpfg: the first word compared with "on"
          std::istringstream in(value);
          std::string word;
          in >> word;
          view_.taperedLines = word == "on";
        }
        if (viewerKeys_.empty()) {
          viewerLine_ = line;
          viewerRaw_ = raw_;
        }
        viewerKeys_ += (viewerKeys_.empty() ? "'" : ", '") + key + ":'";
        return;
      }
    std::vector<std::string> all(std::begin(kReadKeys), std::end(kReadKeys));
    for (const char* k : kViewerKeys) all.emplace_back(k);
    for (const char* k : kFileKeys) all.emplace_back(k);
    error(line, kcol, "unknown view file command '" + key + ":'" + didYouMean(key, all));
  }

  /// The object file `name` a view file line names, which must lie beside the view file or
  /// in a folder below it; nullopt after an error at (line, col) calling it `what`.
  std::optional<std::filesystem::path> objectFile(int line, size_t col, const std::string& name, const std::string& what) {
    const std::filesystem::path folder = std::filesystem::path(view_.file).parent_path().lexically_normal();
    std::filesystem::path file = (folder / name).lexically_normal();
    const std::string rel = file.lexically_relative(folder.empty() ? "." : folder).generic_string();
    if (std::filesystem::path(name).is_absolute() || rel.empty() || rel.rfind("..", 0) == 0) {
      error(line, col, what + " '" + name + "' is outside the object's folder (only files beside the view file, or in folders below it)");
      return std::nullopt;
    }
    return file;
  }

  /// The text of an object file; nullopt after the read's error at (line, col).
  std::optional<std::string> readObjectFile(int line, size_t col, const std::filesystem::path& file) {
    try {
      return readFile(file.string());
    } catch (const std::exception& e) {
      error(line, col, e.what());
      return std::nullopt;
    }
  }

  /// Finds the object file NAME beside the view file (objectFile, `what` names it in
  /// errors), reads it and hands its text and path to parse; a parser's InputError becomes
  /// the file's own diagnostics.
  template <class Parse>
  void parseObjectFile(int line, size_t col, const std::string& name, const std::string& what, Parse parse) {
    const auto found = objectFile(line, col, name, what);
    if (!found) return;
    const auto read = readObjectFile(line, col, *found);
    if (!read) return;
    try {
      parse(*read, found->string());
    } catch (const InputError& e) {
      for (const Diagnostic& d : e.diagnostics()) diags_.add(d);
    }
  }

  /// `NAME [samples]` after `key:` (function and curve lines): the name and the samples
  /// (`fallback` when absent, else a whole number from `minimum` to 1000000); nullopt after
  /// an error.
  std::optional<std::pair<std::string, int>> nameAndSamples(int line, size_t vcol, const std::string& value,
                                                           const std::string& key, int fallback, int minimum) {
    std::istringstream in(value);
    std::string name, extra;
    in >> name;
    if (name.empty()) {
      error(line, vcol, "expected a " + key + " file after '" + key + ":'");
      return std::nullopt;
    }
    if ((in >> extra).fail()) return std::make_pair(name, fallback);
    int v = 0;
    auto r = std::from_chars(extra.data(), extra.data() + extra.size(), v);
    if (r.ec != std::errc() || r.ptr != extra.data() + extra.size() || v < minimum || v > 1000000) {
      error(line, vcol + value.find(extra), "the number of samples after the " + key + " file is a whole number from " +
                                                std::to_string(minimum) + " to 1000000, got '" + extra + "'");
      return std::nullopt;
    }
    const int samples = v;
    if (!(in >> extra).fail()) {
      error(line, vcol + value.rfind(extra), "unexpected '" + extra + "' after '" + key + ": " + name + " " + std::to_string(samples) + "'");
      return std::nullopt;
    }
    return std::make_pair(name, samples);
  }

  /// `function: NAME.func [samples]` (interpret.c, case 52): the function file beside the
  /// view file (or in a folder below it), func(n, x)'s n-th in file order.
  void readFunction(int line, size_t vcol, const std::string& value) {
    const auto head = nameAndSamples(line, vcol, value, "function", -1, 0);
    if (!head) return;
    const auto& [name, samples] = *head;
    // The structured binding reaches the lambda through a copy: clang 14 cannot capture one.
    parseObjectFile(line, vcol, name, "the function file", [&, n = samples](const std::string& text, const std::string& file) {
      view_.functions.push_back(CpfgFunction::parse(text, file, n));
    });
  }

  /// `function set: NAME.fset` (interpret.c, case 55; splinearr.cpp): a function gallery,
  /// `funcgalleryver 1 1`, `items: n`, then n functions in the `fver 1 1` format. It
  /// replaces the functions read so far; cpfg's preprocessor then defines each function's
  /// name (without its suffix) as its number.
  void readFunctionSet(int line, size_t vcol, const std::string& value) {
    const std::string name = trimmed(value);
    if (name.empty() || name.find_first_of(" \t") != std::string::npos) {
      error(line, vcol, "expected one function set file after 'function set:'");
      return;
    }
    const auto found = objectFile(line, vcol, name, "the function set file");
    if (!found) return;
    const std::filesystem::path& file = *found;
    const auto read = readObjectFile(line, vcol, file);
    if (!read) return;
    const std::string& text = *read;
    std::vector<std::string> lines;
    {
      std::istringstream in(text);
      std::string l;
      while (std::getline(in, l)) lines.push_back(l);
    }
    auto fail = [&](size_t l, const std::string& msg) {
      diags_.error(SourceLoc{file.string(), static_cast<int>(l) + 1, 1}, msg, l < lines.size() ? lines[l] : std::string());
    };
    size_t l = 0;
    while (l < lines.size() && trimmed(lines[l]).empty()) ++l;
    if (l >= lines.size() || trimmed(lines[l]) != "funcgalleryver 1 1") {
      fail(l, "expected 'funcgalleryver 1 1' (the function set version cpfg reads)");
      return;
    }
    ++l;
    int items = -1;
    if (l < lines.size()) {
      std::istringstream in(lines[l]);
      std::string key;
      if (!(in >> key >> items) || key != "items:" || items < 0 || items > 10000) items = -1;
    }
    if (items < 0) {
      fail(l, "expected 'items: n' in a function set");
      return;
    }
    // The functions: each from its `fver` line to the next one.
    std::vector<size_t> starts;
    for (size_t k = l + 1; k < lines.size(); ++k)
      if (trimmed(lines[k]).rfind("fver", 0) == 0) starts.push_back(k);
    if (static_cast<int>(starts.size()) != items) {
      fail(l, "'items: " + std::to_string(items) + "' but the set holds " + std::to_string(starts.size()) + " function(s) ('fver' lines)");
      return;
    }
    std::vector<CpfgFunction> set;
    std::vector<std::string> names;
    for (size_t k = 0; k < starts.size(); ++k) {
      const size_t end = k + 1 < starts.size() ? starts[k + 1] : lines.size();
      std::string chunk;
      for (size_t j = starts[k]; j < end; ++j) chunk += lines[j] + "\n";
      try {
        set.push_back(CpfgFunction::parse(chunk, file.string(), -1));
      } catch (const InputError& e) {
        for (Diagnostic d : e.diagnostics()) {
          if (d.loc.line > 0) d.loc.line += static_cast<int>(starts[k]);
          diags_.add(d);
        }
        return;
      }
      std::string n = set.back().name();
      if (size_t dot = n.rfind('.'); dot != std::string::npos) n.erase(dot);
      names.push_back(n);
    }
    view_.functions = std::move(set);
    view_.functionNames = std::move(names);
  }

  /// `contour: id NAME.con` (interpret.c, case 40; general.c): the contour file beside the
  /// view file (or below it) that `@#(id)` selects. At most 31 (cpfg's MAXCONTOURS - 1).
  void readContour(int line, size_t vcol, const std::string& value) {
    std::istringstream in(value);
    std::string idText, name, extra;
    in >> idText >> name;
    int id = 0;
    auto r = std::from_chars(idText.data(), idText.data() + idText.size(), id);
    if (idText.empty() || name.empty() || r.ec != std::errc() || r.ptr != idText.data() + idText.size()) {
      error(line, vcol, "expected 'contour: id FILE.con' (id a whole number)");
      return;
    }
    if (!(in >> extra).fail()) {
      error(line, vcol + value.rfind(extra), "unexpected '" + extra + "' after 'contour: " + idText + " " + name + "'");
      return;
    }
    if (id == 0) {
      error(line, vcol, "contour id 0 is cpfg's circle; a contour file takes another id");
      return;
    }
    for (const CpfgContourEntry& e : view_.contours)
      if (e.id == id) {
        error(line, vcol, "contour id " + idText + " is already used by an earlier 'contour:' line");
        return;
      }
    if (view_.contours.size() >= 31) {
      error(line, vcol, "a view file has at most 31 contours (cpfg's limit)");
      return;
    }
    const size_t ncol = vcol - std::min(vcol, value.find_first_not_of(" \t")) + value.find(name, value.find(idText) + idText.size());
    parseObjectFile(line, ncol, name, "the contour file", [&](const std::string& text, const std::string& file) {
      view_.contours.push_back({id, CpfgContour::parse(text, file)});
    });
  }

  /// `curve: NAME [samples]` (interpret.c, case 53): the curve file beside the view file (or
  /// below it), sampled at samples points (default 100) for arc length.
  void readCurve(int line, size_t vcol, const std::string& value) {
    const auto head = nameAndSamples(line, vcol, value, "curve", CpfgCurve::kDefaultSamples, 2);
    if (!head) return;
    const auto& [name, samples] = *head;
    parseObjectFile(line, vcol, name, "the curve file", [&, n = samples](const std::string& text, const std::string& file) {
      view_.curves.push_back(CpfgCurve::parse(text, file, n));
    });
  }

  /// `surface: X NAME.s [size [s t] [texture]]` (interpret.c, case 21): the surface file
  /// beside the view file (or below it) that `~X` draws, scaled so that its SIZE is size
  /// (default 1; cpfg reads a size <= 0 as 1), tessellated s x t per patch (0 or absent: the
  /// file's precision). A single number after the size is a texture index.
  ///
  /// `line: X NAME.s size [s t [texture]]` (interpret.c, case 20) reads its surface file the
  /// same way and defines the same `~X`; its size is required, and a single number after it
  /// (which cpfg reads and drops) is an error. cpfg also records X as the line type, which
  /// nothing reads (irisGL.c's draw_surface call for it is commented out): F is drawn as
  /// without the line, and so Sprig draws it.
  void readSurface(int line, size_t vcol, const std::string& value, bool lineKey = false) {
    std::vector<std::pair<std::string, size_t>> words;  // each word and its column
    const size_t base = vcol - std::min(vcol, value.find_first_not_of(" \t"));  // the column of value[0]
    for (size_t i = 0; i < value.size();) {
      if (value[i] == ' ' || value[i] == '\t' || value[i] == '\r') {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < value.size() && value[j] != ' ' && value[j] != '\t' && value[j] != '\r') ++j;
      words.emplace_back(value.substr(i, j - i), base + i);
      i = j;
    }
    if (words.size() < (lineKey ? 3u : 2u)) {
      error(line, vcol, lineKey ? "expected 'line: X FILE.s size [s-precision t-precision [texture]]'"
                                : "expected 'surface: X FILE.s [size [s-precision t-precision] [texture]]'");
      return;
    }
    const std::string& id = words[0].first;
    if (id.size() != 1) {
      error(line, words[0].second, "a surface's id is one character (the letter after '~'), got '" + id + "'");
      return;
    }
    if (id == "~") {
      error(line, words[0].second, "cpfg's surface id '~' (a surface only '~~' would draw) is not supported");
      return;
    }
    for (const CpfgSurfaceEntry& e : view_.surfaces)
      if (e.id == id[0]) {
        error(line, words[0].second, "surface id '" + id + "' is already used by an earlier 'surface:' or 'line:' line");
        return;
      }
    if (view_.surfaces.size() >= kMaxSurfaces) {
      error(line, vcol, "a view file has at most " + std::to_string(kMaxSurfaces) + " surfaces (cpfg's limit)");
      return;
    }
    double size = 1.0;
    std::vector<int> ints;
    for (size_t k = 2; k < words.size(); ++k) {
      const std::string& x = words[k].first;
      if (k == 2) {
        auto v = parseFiniteNumber(x);
        if (!v) {
          error(line, words[k].second, "expected the surface's size (a number), got '" + x + "'");
          return;
        }
        size = *v > 0 ? *v : 1.0;
        continue;
      }
      int v = 0;
      auto r = std::from_chars(x.data(), x.data() + x.size(), v);
      if (r.ec != std::errc() || r.ptr != x.data() + x.size() || ints.size() >= 3) {
        error(line, words[k].second, ints.size() >= 3 ? "unexpected '" + x + "' after the surface's texture"
                                                      : "expected a whole number (precision or texture), got '" + x + "'");
        return;
      }
      ints.push_back(v);
    }
    if (lineKey && ints.size() == 1) {
      error(line, words[3].second, "a 'line:' takes two precisions (s t) after its size, then an optional texture; cpfg reads a single number there and drops it");
      return;
    }
    int s = 0, t = 0;
    if (ints.size() >= 2) {
      s = ints[0];
      t = ints[1];
      for (int k = 0; k < 2; ++k)
        if (ints[k] < 0 || ints[k] > CpfgSurface::kMaxPrecision) {
          error(line, words[3 + k].second, "a surface's precision is 0 (the file's) or 1 to " + std::to_string(CpfgSurface::kMaxPrecision) + ", got " + std::to_string(ints[k]));
          return;
        }
    }
    int texture = -1;
    if (ints.size() == 1 || ints.size() == 3) {
      texture = ints.back();
      if (texture < 0) {
        error(line, words.back().second, "a surface's texture is 0 (none) or the number of a 'texture:' line, got " + std::to_string(texture));
        return;
      }
    }
    const std::string& name = words[1].first;
    const auto found = objectFile(line, words[1].second, name, "the surface file");
    if (!found) return;
    const std::filesystem::path& file = *found;
    if (!std::filesystem::exists(file)) {
      // cpfg reads a surface file only when it exists (interpret.c, access()), else the line
      // defines nothing: a '~X' of it in the grammar is then an error.
      warn(line, words[1].second, "the surface file '" + name + "' does not exist: the line is skipped, as cpfg skips it");
      return;
    }
    const auto read = readObjectFile(line, words[1].second, file);
    if (!read) return;
    const std::string& text = *read;
    try {
      view_.surfaces.push_back({id[0], CpfgSurface::parse(text, file.string(), size, s, t), texture});
      if (texture > 0) surfaceTextures_.push_back({line, words.back().second, texture, raw_});
    } catch (const InputError& e) {
      for (const Diagnostic& d : e.diagnostics()) diags_.add(d);
    }
  }

  /// An error that only drawing raises (ViewFile::unsupportedDrawing): the first is kept.
  void drawingError(const Diagnostic& d) {
    if (!view_.unsupportedDrawing) view_.unsupportedDrawing = d;
  }

  /// `background scene: FILE[, FILE...]` (background.c, ReadBackgroundSceneFile: names
  /// separated by spaces, commas or semicolons): the files beside the view file, read as one
  /// scene. Their errors wait for a drawing (cpfg -g derives without them).
  void readBackground(int line, size_t vcol, const std::string& value) {
    std::vector<std::string> texts, names;
    std::string all = value;
    for (char& c : all)
      if (c == ',' || c == ';') c = ' ';
    std::istringstream in(all);
    const SourceLoc at{view_.file, line, static_cast<int>(vcol) + 1};
    for (std::string name; in >> name;) {
      std::filesystem::path file = std::filesystem::path(view_.file).parent_path() / name;
      const std::string rel = file.lexically_normal().lexically_relative(std::filesystem::path(view_.file).parent_path().lexically_normal()).generic_string();
      std::string text;
      try {
        if (std::filesystem::path(name).is_absolute() || rel.empty() || rel.rfind("..", 0) == 0) {
          drawingError(Diagnostic{Severity::Error, at, "the background scene file '" + name + "' is outside the object's folder (only files beside the view file, or in folders below it)", raw_});
          return;
        }
        text = readFile(file.string());
      } catch (const FileReadError& e) {
        drawingError(Diagnostic{Severity::Error, at, "the background scene file '" + name + "': " + e.reason(), raw_});
        return;
      }
      texts.push_back(std::move(text));
      names.push_back(file.lexically_normal().string());
    }
    if (names.empty()) {
      error(line, vcol, "expected 'background scene: FILE[, FILE...]'");
      return;
    }
    try {
      view_.background = parseCpfgBackground(texts, names, warnings_);
    } catch (const InputError& e) {
      drawingError(e.diagnostics().front());
    }
  }

  /// A background cylinder or cone is drawn as cpfg's line style draws F: a solid only in
  /// the cylinder style, tapered (a cone) only with tapered lines on.
  void checkBackgroundTubes() {
    if (!view_.background) return;
    const CpfgBackground& b = *view_.background;
    if (b.firstTube && view_.lineStyle.value_or(CpfgLineStyle::Pixel) != CpfgLineStyle::Cylinder)
      drawingError(Diagnostic{Severity::Error, *b.firstTube,
                              "cpfg draws a background cylinder or cone in the line style of F; Sprig draws it only with 'line style: cylinder' (a solid)", {}});
    if (b.firstCone && !view_.taperedLines)
      drawingError(Diagnostic{Severity::Error, *b.firstCone,
                              "a background cone with 'tapered lines: off' (cpfg draws a cylinder with unequal end discs) is not supported", {}});
  }

  /// `tropism: T: x y z A: angle I: intensity E: elasticity S: step` (movements.c).
  void readTropism(int line, size_t vcol, const std::string& value, bool torque) {
    CpfgTropism t;
    t.torque = torque;
    std::string all;
    for (char c : value) all += (c == ',' || c == ':' || c == '\t') ? ' ' : c;
    std::istringstream in(all);
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    bool haveT = false;
    double intensity = 1;
    DVec3 dir(0);
    for (size_t k = 0; k < words.size();) {
      const std::string sub = words[k++];
      const size_t count = sub == "T" ? 3 : 1;
      if (sub != "T" && sub != "A" && sub != "I" && sub != "E" && sub != "S") {
        error(line, vcol, "unknown tropism subcommand '" + sub + "' (T: A: I: E: S:)");
        return;
      }
      double v[3] = {0, 0, 0};
      for (size_t j = 0; j < count; ++j) {
        auto n = k < words.size() ? parseFiniteNumber(words[k]) : std::nullopt;
        if (!n) {
          error(line, vcol, "tropism subcommand '" + sub + ":' expects " + std::to_string(count) + (count == 1 ? " number" : " numbers"));
          return;
        }
        v[j] = *n;
        ++k;
      }
      if (sub == "T") {
        dir = DVec3(v[0], v[1], v[2]);
        haveT = true;
      } else if (sub == "A") {
        if (!torque) t.angleDeg = v[0];  // cpfg ignores A: in a torque
      } else if (sub == "I") {
        intensity = v[0];
      } else if (sub == "E") {
        t.elasticity = v[0];
      } else {
        t.step = v[0];
      }
    }
    if (!haveT || glm::length(dir) == 0) {
      error(line, vcol, "a tropism needs a non-zero vector 'T: x y z'");
      return;
    }
    if (intensity == 0) {
      error(line, vcol, "a tropism's intensity 'I:' must not be 0");
      return;
    }
    if (view_.tropisms.size() >= size_t(kMaxTropisms)) {
      error(line, vcol, "more than " + std::to_string(kMaxTropisms) + " tropisms and torques (cpfg's limit)");
      return;
    }
    t.direction = glm::normalize(dir) * std::clamp(intensity, -1.0, 1.0);
    view_.tropisms.push_back(t);
  }

  /// `texture: F: NAME.png [H: n|l] [L: n|l|m...] [E: m|d|b] [S] [R: ratio]` (textures.c,
  /// read_texture): cpfg's options are one letter each, separated from their values by
  /// spaces, tabs, colons or commas. The image must be beside the view file or below it.
  void readTexture(int line, size_t vcol, const std::string& value) {
    std::vector<std::pair<std::string, size_t>> words;  // each word and its column
    const size_t base = vcol - std::min(vcol, value.find_first_not_of(" \t"));
    auto sep = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == ':' || c == ','; };
    for (size_t i = 0; i < value.size();) {
      if (sep(value[i])) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < value.size() && !sep(value[j])) ++j;
      words.emplace_back(value.substr(i, j - i), base + i);
      i = j;
    }
    if (view_.textures.size() >= kMaxCpfgTextures) {
      error(line, vcol, "a view file has at most " + std::to_string(kMaxCpfgTextures) + " textures (cpfg's limit)");
      return;
    }
    CpfgTexture tex;
    std::string name;
    size_t nameCol = vcol;
    for (size_t k = 0; k < words.size(); ++k) {
      const std::string& w = words[k].first;
      const size_t col = words[k].second;
      if (w == "S") {
        tex.perSurface = true;
        continue;
      }
      if (w != "F" && w != "H" && w != "L" && w != "E" && w != "R") {
        error(line, col, "unknown texture option '" + w + "' (cpfg's are F: image, H: and L: filters, E: mode, S, R: ratio)");
        return;
      }
      if (k + 1 >= words.size()) {
        error(line, col, "the texture option '" + w + ":' needs a value");
        return;
      }
      const std::string& v = words[++k].first;
      const size_t vc = words[k].second;
      if (w == "F") {
        name = v;
        nameCol = vc;
      } else if (w == "H" || w == "L") {
        if (v == "n" || v == "l") {
          (w == "H" ? tex.magLinear : tex.minLinear) = v == "l";
        } else if (w == "L" && v[0] == 'm' && v.size() <= 3 && v.find_first_not_of("nl", 1) == std::string::npos) {
          // textures.c: m is GL_LINEAR_MIPMAP_LINEAR; m followed by n or l names the filter
          // within a level, then n selects GL_*_MIPMAP_NEAREST (anything else _LINEAR).
          tex.mipmap = true;
          tex.minLinear = v.size() < 2 || v[1] == 'l';
          tex.mipLinear = v.size() < 3 || v[2] != 'n';
        } else {
          error(line, vc, "a texture filter '" + w + ":' is n (nearest) or l (linear)" +
                              (w == "L" ? std::string(", or m, mn, ml, mnn, mnl, mln, mll (mipmaps)") : std::string()) +
                              ", got '" + v + "'");
          return;
        }
      } else if (w == "E") {
        if (v == "m" || v == "d" || v == "b") {
          tex.decal = v == "d";
          tex.blend = v == "b";
        } else {
          error(line, vc, "a texture mode 'E:' is m (modulate), d (decal) or b (blend), got '" + v + "'");
          return;
        }
      } else {
        auto r = parseFiniteNumber(v);
        if (!r || !(*r > 0)) {
          error(line, vc, "a texture's ratio 'R:' is a number greater than 0, got '" + v + "'");
          return;
        }
        tex.ratio = *r;
      }
    }
    if (name.empty()) {
      error(line, vcol, "a texture needs its image: 'texture: F: NAME.png'");
      return;
    }
    const auto found = objectFile(line, nameCol, name, "the texture image");
    if (!found) return;
    const std::filesystem::path& file = *found;
    tex.file = file.string();
    try {
      requireRegularFile(file);
      Image img = readImage(file);
      if (img.width <= 0 || img.height <= 0) throw ImageReadError(file, "the image has no pixels");
      // readImage's colour comes multiplied by alpha in the file's encoding (OpenImageIO
      // multiplies the sRGB values of 8-bit files): divided back there, to straight alpha.
      const bool srgb = readImageInfo(file).srgb;
      for (size_t p = 0; p + 3 < img.pixels.size(); p += 4) {
        const float a = img.pixels[p + 3];
        if (a < 0.999f) tex.transparent = true;
        if (a > 0.0f && a < 1.0f)
          for (size_t c = 0; c < 3; ++c) {
            float& v = img.pixels[p + c];
            v = srgb ? srgbToLinear(std::min(linearToSrgb(v) / a, 1.0f)) : std::min(v / a, 1.0f);
          }
      }
      tex.image = std::make_shared<const Image>(std::move(img));
      if (tex.mipmap) tex.buildMipmaps(srgb);
    } catch (const FileReadError& e) {
      unreadable(tex, line, nameCol, e.what());
    } catch (const ImageReadError& e) {
      unreadable(tex, line, nameCol, "cannot read the texture image '" + file.string() + "': " + e.reason());
    } catch (const std::exception& e) {
      unreadable(tex, line, nameCol, "cannot read the texture image '" + file.string() + "': " + e.what());
    }
    view_.textures.push_back(std::move(tex));
  }

  /// An image that could not be read: its error waits in the texture until an organ drawn
  /// with it needs it (cpfg reads no image to derive).
  void unreadable(CpfgTexture& tex, int line, size_t col0, const std::string& msg) {
    tex.image.reset();
    tex.levels.clear();
    Diagnostic d;
    d.loc = SourceLoc{view_.file, line, static_cast<int>(col0) + 1};
    d.message = msg;
    d.sourceLine = raw_;
    tex.unreadable = std::move(d);
  }

  /// A `surface:` line's texture number, checked against the `texture:` lines at the end.
  struct SurfaceTexture {
    int line;
    size_t col;
    int texture;
    std::string raw;
  };
  std::vector<SurfaceTexture> surfaceTextures_;

  ViewFile view_;
  DiagnosticList diags_;
  std::vector<Diagnostic> warnings_;
  size_t warningsNotKept_ = 0;  ///< warnings past kMaxDiagnostics, counted only
  std::string raw_;
  std::string viewerKeys_;  ///< the viewer keys read, for one warning
  int viewerLine_ = 0;      ///< the line of the first
  std::string viewerRaw_;
};

}  // namespace

ViewFile parseViewFile(const std::string& text, const std::string& fileName) { return ViewParser(fileName).run(text); }

ViewFile loadViewFile(const std::string& path) {
  std::string text;
  try {
    text = readFile(path);
  } catch (const FileReadError& e) {
    throw InputError(SourceLoc{path, 0, 0}, e.reason());
  }
  return parseViewFile(text, path);
}

TurtleSettings cpfgTurtleSettings(const ViewFile* view, TurtleSettings t) {
  const ViewFile none;
  const ViewFile& v = view ? *view : none;
  t.cpfg = true;
  t.interpretPastCut = v.interpretPastCut;
  t.gcTwist = v.twistCylinders;
  t.angleDeg = v.angleDeg.value_or(kCpfgDefaultAngleDeg);
  t.initialWidth = v.lineWidth.value_or(kCpfgDefaultLineWidth);
  t.widthIncrement = v.widthIncrement.value_or(0.0);
  t.initialColor = v.initialColor.value_or(kCpfgDefaultColor);
  t.colorIncrement = v.colorIncrement.value_or(1);
  t.initialScale = v.initialScale.value_or(1.0);
  t.scaleMultiplier = v.scaleMultiplier.value_or(1.0);
  t.tropisms = v.tropisms;
  t.cpfgSurfaces = v.surfaces.empty() ? nullptr : std::make_shared<const std::vector<CpfgSurfaceEntry>>(v.surfaces);
  t.cpfgTextures = v.textures.empty() ? nullptr : std::make_shared<const std::vector<CpfgTexture>>(v.textures);
  t.cpfgContours = v.contours.empty() ? nullptr : std::make_shared<const std::vector<CpfgContourEntry>>(v.contours);
  t.contourSides = v.contourSides.value_or(CpfgContour::kDefaultSides);
  // cpfg's old tropism (its defaults: direction +Y, elasticity 0, increment 0).
  t.tropism = v.oldTropismDirection.value_or(DVec3(0, 1, 0));
  t.elasticity = v.oldElasticity.value_or(0.0);
  t.elasticityIncrement = v.oldElasticityIncrement.value_or(0.0);
  if (v.lineStyle.value_or(CpfgLineStyle::Pixel) != CpfgLineStyle::Pixel) {
    t.widthScale = 1.0;
    t.maxWidthToLength = 0.0;
  }
  return t;
}

std::string cpfgDefaultsUsed(const ViewFile* view) {
  const ViewFile none;
  const ViewFile& v = view ? *view : none;
  std::string out;
  auto add = [&](const std::string& s) { out += (out.empty() ? "" : ", ") + s; };
  if (!v.angleDeg) add("angle increment 45");
  if (!v.lineWidth) add("initial line width 1 (pixels)");
  if (!v.widthIncrement) add("line width increment 0");
  if (!v.initialColor) add("initial color 128");
  if (!v.colorIncrement) add("color increment 1");
  if (!v.initialScale) add("initial scale 1");
  if (v.tropisms.empty()) add("no tropism");
  return out;
}

}  // namespace sprig::lsystem
