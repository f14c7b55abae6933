#include "lsystem/cpfg_background.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "lsystem/detail/scanner.h"

namespace sprig::lsystem {

namespace {

using detail::isIdentChar;
using detail::isIdentStart;
using Kind = CpfgBackgroundPrimitive::Kind;

/// A word of the preprocessed text with where it was written.
struct Word {
  std::string text;
  SourceLoc loc;
  std::string sourceLine;
};

/// Largest magnitude of a number and of a matrix entry: positions stay finite in floats.
constexpr double kMaxMagnitude = 1e15;

/// The commands of background.c's syntax table.
enum class Command { Material, Push, Pop, Translate, Rotate, Scale, MultMatrix, Draw };

struct CommandName {
  const char* name;
  Command command;
  Kind kind;  ///< for Draw
};

constexpr CommandName kCommands[] = {
    {"polygon", Command::Draw, Kind::Polygon},     {"polygonuv", Command::Draw, Kind::PolygonUV},
    {"rectangle", Command::Draw, Kind::Rectangle}, {"mesh", Command::Draw, Kind::Mesh},
    {"prism", Command::Draw, Kind::Box},           {"box", Command::Draw, Kind::Box},
    {"cone", Command::Draw, Kind::Cone},           {"cylinder", Command::Draw, Kind::Cylinder},
    {"sphere", Command::Draw, Kind::Sphere},       {"material", Command::Material, Kind::Polygon},
    {"pushmatrix", Command::Push, Kind::Polygon},  {"popmatrix", Command::Pop, Kind::Polygon},
    {"translate", Command::Translate, Kind::Polygon}, {"rotate", Command::Rotate, Kind::Polygon},
    {"scale", Command::Scale, Kind::Polygon},      {"multmatrix", Command::MultMatrix, Kind::Polygon},
};

/// line with each identifier that names a macro replaced by its text, rescanned until no
/// macro is left (at most 32 rounds: a self-referring macro stops there); nullopt once the
/// text grows past budget characters (a macro naming itself twice doubles every round) or
/// the characters written by every round of the file's expansions so far (work) pass
/// kMaxBackgroundExpansionWork.
std::optional<std::string> expand(const std::string& line, const std::map<std::string, std::string>& macros, size_t budget,
                                  size_t& work) {
  std::string s = line;
  for (int round = 0; round < 32; ++round) {
    std::string out;
    bool changed = false;
    for (size_t i = 0; i < s.size();) {
      if (isIdentStart(s[i]) && (i == 0 || !isIdentChar(s[i - 1]))) {
        size_t j = i;
        while (j < s.size() && isIdentChar(s[j])) ++j;
        const auto it = macros.find(s.substr(i, j - i));
        if (it != macros.end()) {
          out += it->second;
          changed = true;
          if (out.size() > budget) return std::nullopt;
        } else {
          out += s.substr(i, j - i);
        }
        i = j;
      } else {
        out += s[i++];
      }
    }
    if (!changed) break;
    work += out.size();
    if (work > kMaxBackgroundExpansionWork) return std::nullopt;
    s = std::move(out);
  }
  return s;
}

/// text with its `/* */` comments blanked (newlines kept); pending gets the (line, 0-based
/// column) of one never closed. cpfg's `preproc` removes no `//` comment: its words are
/// read as commands.
std::string blankBlockComments(std::string text, std::pair<int, int>& pending) {
  int line = 1;
  size_t lineStart = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      lineStart = i + 1;
      continue;
    }
    if (text[i] != '/' || i + 1 >= text.size() || text[i + 1] != '*') continue;
    const size_t close = text.find("*/", i + 2);
    if (close == std::string::npos) {
      pending = {line, static_cast<int>(i - lineStart)};
      text.resize(i);  // the rest is the comment
      break;
    }
    for (size_t j = i; j < close + 2; ++j)
      if (text[j] == '\n') {
        ++line;
        lineStart = j + 1;
      } else {
        text[j] = ' ';
      }
    i = close + 1;
  }
  return text;
}

/// The words of one file after cpfg's preprocessor: block comments blanked, `#define NAME text`
/// lines read, other directives errors, macros expanded (a macro's words sit at its column).
void tooLong(const SourceLoc& at, const std::string& sourceLine, DiagnosticList& diags) {
  diags.error(at, "the macros expand this background scene file beyond " + std::to_string(kMaxBackgroundExpansion) +
                      " characters, or rescan it beyond " + std::to_string(kMaxBackgroundExpansionWork) + " (Sprig's limits)",
              sourceLine);
}

void preprocess(const std::string& text, const std::string& file, std::vector<Word>& words, DiagnosticList& diags) {
  size_t expandedChars = 0, work = 0;
  std::pair<int, int> pending{0, 0};
  const std::string clean = blankBlockComments(text, pending);
  if (pending.first) diags.error(SourceLoc{file, pending.first, pending.second + 1}, "unterminated comment '/*'", lineOf(text, pending.first));
  const std::vector<std::string> lines = detail::splitAtNewlines(clean);
  std::map<std::string, std::string> macros;
  for (size_t k = 0; k < lines.size(); ++k) {
    const std::string& l = lines[k];
    const int lineNo = static_cast<int>(k) + 1;
    const size_t first = l.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    if (l[first] == '#') {
      size_t d = l.find_first_not_of(" \t", first + 1);
      size_t e = d;
      while (e < l.size() && isIdentChar(l[e])) ++e;
      const std::string directive = d == std::string::npos ? "" : l.substr(d, e - d);
      size_t n = l.find_first_not_of(" \t", e);
      size_t ne = n;
      while (ne < l.size() && isIdentChar(l[ne])) ++ne;
      if (directive == "define" && n != std::string::npos && isIdentStart(l[n]) && (ne == l.size() || l[ne] != '(')) {
        const size_t v = l.find_first_not_of(" \t", ne);
        const std::optional<std::string> body = v == std::string::npos ? std::string() : expand(l.substr(v), macros, kMaxBackgroundExpansion, work);
        if (!body) return tooLong(SourceLoc{file, lineNo, static_cast<int>(first) + 1}, lineOf(text, lineNo), diags);
        macros[l.substr(n, ne - n)] = *body;
      } else {
        diags.error(SourceLoc{file, lineNo, static_cast<int>(first) + 1},
                    directive == "define" ? "only '#define NAME text' (a macro without parameters) is supported in a background scene file"
                                          : "C preprocessor directive '#" + directive + "' in a background scene file is not supported",
                    lineOf(text, lineNo));
      }
      continue;
    }
    for (size_t i = 0; i < l.size();) {
      if (l[i] == ' ' || l[i] == '\t' || l[i] == '\r') {
        ++i;
        continue;
      }
      size_t j = i;
      while (j < l.size() && l[j] != ' ' && l[j] != '\t' && l[j] != '\r') ++j;
      const std::string word = l.substr(i, j - i);
      const std::optional<std::string> expanded = expand(word, macros, kMaxBackgroundExpansion - expandedChars, work);
      if (!expanded) return tooLong(SourceLoc{file, lineNo, static_cast<int>(i) + 1}, lineOf(text, lineNo), diags);
      if (*expanded != word) expandedChars += expanded->size();  // only what macros wrote counts
      std::istringstream in(*expanded);
      for (std::string w; in >> w;) words.push_back({w, SourceLoc{file, lineNo, static_cast<int>(i) + 1}, lineOf(text, lineNo)});
      i = j;
    }
  }
}

/// Whether n numbers suit the command (pushmatrix and popmatrix take none).
std::string countError(const CommandName& c, size_t n) {
  auto expects = [&](const std::string& what) { return "'" + std::string(c.name) + "' expects " + what + ", got " + std::to_string(n) + (n == 1 ? " number" : " numbers"); };
  switch (c.command) {
    case Command::Material:
      return n == 4 || n == 8 || n == 12 || n == 16 || n == 17 ? "" : expects("4, 8, 12, 16 or 17 numbers (ambient, diffuse, specular, emissive red green blue alpha; shininess)");
    case Command::Push:
    case Command::Pop: return n == 0 ? "" : expects("no numbers");
    case Command::Translate:
    case Command::Scale: return n == 3 ? "" : expects("3 numbers (x y z)");
    case Command::Rotate: return n == 4 ? "" : expects("4 numbers (degrees, then the axis x y z)");
    case Command::MultMatrix: return n == 16 ? "" : expects("16 numbers (a 4 x 4 matrix, column by column)");
    case Command::Draw: break;
  }
  switch (c.kind) {
    case Kind::Polygon: return n >= 9 && n % 3 == 0 ? "" : expects("3 or more vertices (x y z each)");
    case Kind::PolygonUV: return n >= 18 && n % 6 == 0 ? "" : expects("3 or more vertices with normals (x y z nx ny nz each)");
    case Kind::Rectangle:
      if (n == 5) return "a rectangle's fifth number (a factor of its emission) is not supported";
      return n == 2 || n == 4 ? "" : expects("2 or 4 numbers (a b [x0 y0])");
    case Kind::Mesh: return n >= 12 && n % 6 == 0 ? "" : expects("4 + 2k vertices (x y z each)");
    case Kind::Box: return n == 3 ? "" : expects("3 numbers (a b c)");
    case Kind::Sphere: return n == 1 ? "" : expects("1 number (the radius)");
    case Kind::Cylinder: return n == 2 ? "" : expects("2 numbers (r h)");
    case Kind::Cone: return n == 3 ? "" : expects("3 numbers (r1 r2 h)");
  }
  return "";
}

/// Runs one command's effect on the scene: the matrix stack, the material, or a primitive.
class SceneBuilder {
 public:
  SceneBuilder(CpfgBackground& scene, DiagnosticList& diags, std::vector<Diagnostic>& warnings)
      : scene_(scene), diags_(diags), warnings_(warnings) {}

  void run(const CommandName& c, const Word& w, const std::vector<double>& v) {
    auto fail = [&](const std::string& m) { diags_.error(w.loc, m, w.sourceLine); };
    glm::dmat4& top = stack_.back();
    switch (c.command) {
      case Command::Push:
        if (static_cast<int>(stack_.size()) > kMaxBackgroundStack) return fail("the matrix stack is full (" + std::to_string(kMaxBackgroundStack) + " pushmatrix deep, cpfg's limit)");
        stack_.push_back(glm::dmat4(top));
        return;
      case Command::Pop:
        if (stack_.size() == 1) return fail("'popmatrix' without its 'pushmatrix'");
        stack_.pop_back();
        return;
      case Command::Translate: top = glm::translate(top, DVec3(v[0], v[1], v[2])); return;
      case Command::Scale: top = glm::scale(top, DVec3(v[0], v[1], v[2])); return;
      case Command::Rotate: {
        const DVec3 axis(v[1], v[2], v[3]);
        if (glm::length(axis) == 0) return fail("a rotation about the zero vector");
        top = glm::rotate(top, glm::radians(v[0]), glm::normalize(axis));
        return;
      }
      case Command::MultMatrix:
        if (v[3] != 0 || v[7] != 0 || v[11] != 0 || v[15] != 1)
          return fail("a projective 'multmatrix' (its numbers 4, 8, 12 and 16 not 0 0 0 1) is not supported");
        top = top * glm::make_mat4(v.data());
        return;
      case Command::Material: material(w, v); return;
      case Command::Draw: break;
    }
    for (int col = 0; col < 4; ++col)
      for (int row = 0; row < 4; ++row)
        if (!(std::abs(top[col][row]) <= kMaxMagnitude)) return fail("the transformation grows beyond 1e15 (Sprig's limit)");
    if (scene_.materials.empty()) return fail("a primitive before the first 'material' (cpfg draws it in the colour of its colour map's entry 256, which Sprig does not read)");
    if ((c.kind == Kind::Sphere && v[0] < 0) || (c.kind == Kind::Cylinder && v[0] < 0) || (c.kind == Kind::Cone && (v[0] < 0 || v[1] < 0)))
      return fail("a negative radius");
    if (c.kind == Kind::Cylinder || c.kind == Kind::Cone) {
      if (!scene_.firstTube) scene_.firstTube = w.loc;
      if (c.kind == Kind::Cone && !scene_.firstCone) scene_.firstCone = w.loc;
    }
    triangles_ += triangleCount(c.kind, v.size());
    if (triangles_ > kMaxBackgroundTriangles)
      return fail("the background scene has more than " + std::to_string(kMaxBackgroundTriangles) + " triangles (Sprig's limit)");
    scene_.primitives.push_back({c.kind, top, v, static_cast<int>(scene_.materials.size()) - 1, w.loc});
  }

  /// At most the triangles a primitive of n numbers draws (MeshWriter).
  static size_t triangleCount(Kind kind, size_t n) {
    constexpr size_t sides = 48;
    switch (kind) {
      case Kind::Polygon: return n / 3 - 2;
      case Kind::PolygonUV: return n / 6 - 2;
      case Kind::Rectangle: return 2;
      case Kind::Mesh: return (n / 3 - 2);
      case Kind::Box: return 12;
      case Kind::Sphere: return 2 * sides * (sides / 2) - 2 * sides;
      case Kind::Cylinder:
      case Kind::Cone: return 2 * sides + 2 * (sides - 2);
    }
    return 0;
  }

 private:
  void material(const Word& w, const std::vector<double>& v) {
    if (v.size() < 8 && scene_.materials.empty()) {
      diags_.error(w.loc, "the first 'material' sets no diffuse colour (8 numbers or more)", w.sourceLine);
      return;
    }
    CpfgBackgroundMaterial m = scene_.materials.empty() ? CpfgBackgroundMaterial{} : scene_.materials.back();
    if (v.size() >= 8) {
      m.diffuse = Vec3(static_cast<float>(v[4]), static_cast<float>(v[5]), static_cast<float>(v[6]));
      m.alpha = static_cast<float>(v[7]);
    }
    bool translucent = v.size() >= 8 && v[7] < 1;
    for (size_t a = 11; a < v.size() && a <= 15; a += 4) translucent = translucent || v[a] < 1;
    if (translucent) {
      Diagnostic d;
      d.severity = Severity::Warning;
      d.loc = w.loc;
      d.message = "a translucent material (an alpha below 1): cpfg blends it, Sprig draws it opaque";
      d.sourceLine = w.sourceLine;
      warnings_.push_back(d);
    }
    scene_.materials.push_back(m);
  }

  CpfgBackground& scene_;
  DiagnosticList& diags_;
  std::vector<Diagnostic>& warnings_;
  std::vector<glm::dmat4> stack_{glm::dmat4(1.0)};
  size_t triangles_ = 0;
};

/// Adds triangles of one primitive to a mesh, moving local points into the scene.
class MeshWriter {
 public:
  MeshWriter(CpfgBackgroundMesh& mesh, const CpfgBackgroundPrimitive& p)
      : m_(mesh), sceneFromLocal_(p.sceneFromLocal), normalFromLocal_(glm::transpose(glm::inverse(glm::dmat3(p.sceneFromLocal)))), material_(p.material) {}

  /// A vertex at local point p with local normal n (a normal already in the scene when
  /// sceneNormal); returns its index.
  uint32_t vertex(const DVec3& p, const DVec3& n, bool sceneNormal = false) {
    m_.positions.push_back(DVec3(sceneFromLocal_ * glm::dvec4(p, 1.0)));
    const DVec3 sn = sceneNormal ? n : normalFromLocal_ * n;
    const double len = glm::length(sn);  // a singular matrix (a zero scale) has no normals: +y
    m_.normals.push_back(std::isfinite(len) && len > 0 ? sn / len : DVec3(0, 1, 0));
    return static_cast<uint32_t>(m_.positions.size() - 1);
  }

  /// A triangle of vertices, wound so that its face agrees with their normals.
  void triangle(uint32_t a, uint32_t b, uint32_t c) {
    const DVec3 face = glm::cross(m_.positions[b] - m_.positions[a], m_.positions[c] - m_.positions[a]);
    if (glm::dot(face, m_.normals[a] + m_.normals[b] + m_.normals[c]) < 0) std::swap(b, c);
    m_.triangles.insert(m_.triangles.end(), {a, b, c});
    m_.triangleMaterials.push_back(material_);
  }

  /// A flat polygon of local points (a fan from the first), its normal from the first three.
  void polygon(const std::vector<DVec3>& pts) {
    DVec3 n = glm::cross(pts[1] - pts[0], pts[2] - pts[0]);
    if (glm::length(n) == 0) n = DVec3(0, 1, 0);
    std::vector<uint32_t> ids;
    for (const DVec3& p : pts) ids.push_back(vertex(p, n));
    for (size_t k = 1; k + 1 < ids.size(); ++k) triangle(ids[0], ids[k], ids[k + 1]);
  }

  /// A disc of radius r at height y (axis +y), facing +y (up) or -y.
  void disc(double r, double y, bool up) {
    if (r == 0) return;
    std::vector<DVec3> pts;
    for (int k = 0; k < kSides; ++k) {
      const double a = 2 * M_PI * k / kSides;
      pts.push_back(DVec3(r * std::cos(a), y, r * std::sin(a)));
    }
    if (!up) std::reverse(pts.begin(), pts.end());
    polygon(pts);
  }

  /// A capped tube from radius r1 at y = 0 to r2 at y = h.
  void tube(double r1, double r2, double h) {
    const double slope = h != 0 ? (r1 - r2) / h : 0;
    std::vector<uint32_t> ring;
    for (int k = 0; k <= kSides; ++k) {
      const double a = 2 * M_PI * k / kSides;
      const DVec3 radial(std::cos(a), 0, std::sin(a));
      const DVec3 n = radial + DVec3(0, slope, 0);
      ring.push_back(vertex(r1 * radial, n));
      ring.push_back(vertex(r2 * radial + DVec3(0, h, 0), n));
    }
    if (h != 0)
      for (int k = 0; k < kSides; ++k) {
        const uint32_t a = ring[2 * k], b = ring[2 * k + 1], c = ring[2 * k + 2], d = ring[2 * k + 3];
        triangle(a, b, d);
        triangle(a, d, c);
      }
    disc(r1, 0, h < 0);
    disc(r2, h, h >= 0);
  }

  /// A sphere of radius r about the local origin.
  void sphere(double r) {
    if (r == 0) return;
    const int rings = kSides / 2;
    std::vector<uint32_t> ids;
    for (int i = 0; i <= rings; ++i)
      for (int k = 0; k <= kSides; ++k) {
        const double t = M_PI * i / rings, a = 2 * M_PI * k / kSides;
        const DVec3 n(std::sin(t) * std::cos(a), std::cos(t), std::sin(t) * std::sin(a));
        ids.push_back(vertex(r * n, n));
      }
    const int row = kSides + 1;
    for (int i = 0; i < rings; ++i)
      for (int k = 0; k < kSides; ++k) {
        const uint32_t a = ids[i * row + k], b = ids[i * row + k + 1], c = ids[(i + 1) * row + k], d = ids[(i + 1) * row + k + 1];
        if (i > 0) triangle(a, b, d);
        if (i + 1 < rings) triangle(a, d, c);
      }
  }

  static constexpr int kSides = 48;

 private:
  CpfgBackgroundMesh& m_;
  glm::dmat4 sceneFromLocal_;
  glm::dmat3 normalFromLocal_;
  int material_;
};

/// The local points of a numbers list, stride numbers apart.
std::vector<DVec3> points(const std::vector<double>& v, size_t stride) {
  std::vector<DVec3> out;
  for (size_t k = 0; k + 2 < v.size(); k += stride) out.push_back(DVec3(v[k], v[k + 1], v[k + 2]));
  return out;
}

void writePrimitive(CpfgBackgroundMesh& mesh, const CpfgBackgroundPrimitive& p) {
  MeshWriter w(mesh, p);
  const std::vector<double>& v = p.numbers;
  switch (p.kind) {
    case Kind::Polygon: w.polygon(points(v, 3)); return;
    case Kind::PolygonUV: {
      // Per-vertex normals as written (cpfg's Transform3Vector moves them by the matrix).
      std::vector<uint32_t> ids;
      for (size_t k = 0; k + 5 < v.size(); k += 6)
        ids.push_back(w.vertex(DVec3(v[k], v[k + 1], v[k + 2]), glm::dmat3(p.sceneFromLocal) * DVec3(v[k + 3], v[k + 4], v[k + 5]), true));
      for (size_t k = 1; k + 1 < ids.size(); ++k) w.triangle(ids[0], ids[k], ids[k + 1]);
      return;
    }
    case Kind::Rectangle: {
      const double x = v.size() == 4 ? v[2] : 0, y = v.size() == 4 ? v[3] : 0;
      w.polygon({DVec3(x, y, 0), DVec3(x + v[0], y, 0), DVec3(x + v[0], y + v[1], 0), DVec3(x, y + v[1], 0)});
      return;
    }
    case Kind::Mesh: {
      // background.c: vertices 2k, 2k+1, 2k+2, 2k+3 make one quad (2k, 2k+2, 2k+3, 2k+1).
      const std::vector<DVec3> pts = points(v, 3);
      for (size_t k = 0; k + 3 < pts.size(); k += 2) w.polygon({pts[k], pts[k + 2], pts[k + 3], pts[k + 1]});
      return;
    }
    case Kind::Box: {
      auto P = [&](int x, int y, int z) { return DVec3(x * v[0], y * v[1], z * v[2]); };
      w.polygon({P(0, 0, 0), P(0, 0, 1), P(0, 1, 1), P(0, 1, 0)});
      w.polygon({P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1)});
      w.polygon({P(0, 0, 0), P(0, 1, 0), P(1, 1, 0), P(1, 0, 0)});
      w.polygon({P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1)});
      w.polygon({P(0, 0, 0), P(0, 0, 1), P(1, 0, 1), P(1, 0, 0)});
      w.polygon({P(0, 1, 0), P(1, 1, 0), P(1, 1, 1), P(0, 1, 1)});
      return;
    }
    case Kind::Sphere: w.sphere(v[0]); return;
    case Kind::Cylinder: w.tube(v[0], v[0], v[1]); return;
    case Kind::Cone: w.tube(v[0], v[1], v[2]); return;
  }
}

}  // namespace

CpfgBackgroundMesh CpfgBackground::triangulate() const {
  CpfgBackgroundMesh mesh;
  for (const CpfgBackgroundPrimitive& p : primitives) writePrimitive(mesh, p);
  return mesh;
}

CpfgBackground parseCpfgBackground(const std::vector<std::string>& texts, const std::vector<std::string>& fileNames,
                                   std::vector<Diagnostic>& warnings) {
  DiagnosticList diags;
  std::vector<Word> words;
  for (size_t f = 0; f < texts.size(); ++f) preprocess(texts[f], fileNames[f], words, diags);
  CpfgBackground scene;
  SceneBuilder builder(scene, diags, warnings);
  size_t commands = 0;
  for (size_t i = 0; i < words.size();) {
    const Word& w = words[i++];
    std::vector<double> v;
    for (; i < words.size(); ++i) {
      auto n = parseFiniteNumber(words[i].text);
      if (!n) break;
      if (std::abs(*n) > kMaxMagnitude) diags.error(words[i].loc, "a number beyond 1e15 in magnitude (Sprig's limit)", words[i].sourceLine);
      v.push_back(*n);
    }
    const CommandName* c = nullptr;
    for (const CommandName& k : kCommands)
      if (w.text == k.name) c = &k;
    if (!c) {
      std::vector<std::string> names;
      for (const CommandName& k : kCommands) names.emplace_back(k.name);
      diags.error(w.loc,
                  parseFiniteNumber(w.text) ? "a number '" + w.text + "' where a background scene command goes"
                                            : "unknown background scene command '" + w.text + "'" + didYouMean(w.text, names),
                  w.sourceLine);
      continue;
    }
    if (++commands > kMaxBackgroundCommands) {
      diags.error(w.loc, "more than " + std::to_string(kMaxBackgroundCommands) + " background scene commands (Sprig's limit)", w.sourceLine);
      break;
    }
    const std::string bad = countError(*c, v.size());
    if (!bad.empty()) {
      diags.error(w.loc, bad, w.sourceLine);
      continue;
    }
    builder.run(*c, w, v);
  }
  diags.throwIfErrors();
  return scene;
}

}  // namespace sprig::lsystem
