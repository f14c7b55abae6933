#include "lsystem/cpfg_surface.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/diagnostics.h"

namespace sprig::lsystem {

namespace {

/// A word of the file with its 0-based position. A word ends at a space or after a ':'
/// (so `SIZE:1.0` reads as `SIZE:` and `1.0`, as fscanf's "SIZE: %f" does).
struct Token {
  std::string text;
  size_t line = 0, col = 0;
};

/// The words of a surface file, read in order, with positions for errors.
struct Tokens {
  std::string file;
  std::vector<std::string> lines;
  std::vector<Token> words;
  size_t next = 0;

  [[noreturn]] void fail(size_t line, size_t col, const std::string& msg) const {
    throw InputError(SourceLoc{file, static_cast<int>(line + 1), static_cast<int>(col + 1)}, msg,
                     line < lines.size() ? lines[line] : std::string());
  }
  [[noreturn]] void failAtEnd(const std::string& what) const {
    const size_t l = lines.empty() ? 0 : lines.size() - 1;
    fail(l, l < lines.size() ? lines[l].size() : 0, "the surface file ends before " + what);
  }
  bool done() const { return next >= words.size(); }
  const Token& peek() const { return words[next]; }
  /// The next word, which must be key.
  void expect(const char* key, const char* what) {
    if (done()) failAtEnd(std::string("'") + key + "' (" + what + ")");
    const Token& t = words[next];
    if (t.text != key) fail(t.line, t.col, std::string("expected '") + key + "' (" + what + "), got '" + t.text + "'");
    ++next;
  }
  /// The next word as a finite number.
  double number(const char* what) {
    if (done()) failAtEnd(what);
    const Token& t = words[next];
    double v = 0;
    auto r = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
    if (r.ec != std::errc() || r.ptr != t.text.data() + t.text.size() || !std::isfinite(v))
      fail(t.line, t.col, std::string("expected a number (") + what + "), got '" + t.text + "'");
    ++next;
    return v;
  }
  /// The next word as a whole number.
  int whole(const char* what) {
    const Token& t = done() ? Token{} : words[next];
    const double v = number(what);
    if (v != std::floor(v) || std::fabs(v) > 1e9) fail(t.line, t.col, std::string("expected a whole number (") + what + "), got '" + t.text + "'");
    return static_cast<int>(v);
  }
  /// The next word, whatever it is.
  const Token& word(const char* what) {
    if (done()) failAtEnd(what);
    return words[next++];
  }
  /// `KEY X: x Y: y Z: z`, KEY being one or two words.
  DVec3 vector(const char* key1, const char* key2, const char* what) {
    expect(key1, what);
    if (key2) expect(key2, what);
    DVec3 v;
    expect("X:", what);
    v.x = number(what);
    expect("Y:", what);
    v.y = number(what);
    expect("Z:", what);
    v.z = number(what);
    return v;
  }
};

Tokens tokenize(const std::string& text, const std::string& fileName) {
  Tokens ts;
  ts.file = fileName;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    ts.lines.push_back(line);
    const size_t l = ts.lines.size() - 1;
    size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      if (i >= line.size()) break;
      size_t j = i;
      while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') {
        ++j;
        if (line[j - 1] == ':') break;
      }
      ts.words.push_back({line.substr(i, j - i), l, i});
      i = j;
    }
  }
  return ts;
}

double bernstein(int i, double u) {
  const double v = 1 - u;
  switch (i) {
    case 0: return v * v * v;
    case 1: return 3 * u * v * v;
    case 2: return 3 * u * u * v;
    default: return u * u * u;
  }
}

double bernsteinDerivative(int i, double u) {
  const double v = 1 - u;
  switch (i) {
    case 0: return -3 * v * v;
    case 1: return 3 * v * v - 6 * u * v;
    case 2: return 6 * u * v - 3 * u * u;
    default: return 3 * u * u;
  }
}

/// The neighbour keys in cpfg's order; the opposite of key n is key 7 - n.
constexpr const char* kNeighbourKeys[8] = {"AL:", "A:", "AR:", "L:", "R:", "BL:", "B:", "BR:"};

}  // namespace

DVec3 CpfgSurface::point(size_t patch, double s, double t) const {
  DVec3 sum(0.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) sum += bernstein(i, s) * bernstein(j, t) * patches_[patch].points[i][j];
  return sum;
}

DVec3 CpfgSurface::normal(size_t patch, double s, double t) const {
  DVec3 ds(0.0), dt(0.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      ds += bernsteinDerivative(i, s) * bernstein(j, t) * patches_[patch].points[i][j];
      dt += bernstein(i, s) * bernsteinDerivative(j, t) * patches_[patch].points[i][j];
    }
  const DVec3 n = glm::cross(dt, ds);
  const double len = glm::length(n);
  return len > 0 ? n / len : DVec3(0, 1, 0);
}

void CpfgSurface::tessellate() {
  const uint32_t cols = static_cast<uint32_t>(tPrecision_) + 1;
  for (size_t p = 0; p < patches_.size(); ++p) {
    const uint32_t base = static_cast<uint32_t>(vertices_.size());
    for (int s = 0; s <= sPrecision_; ++s)
      for (int t = 0; t <= tPrecision_; ++t) {
        const double u = double(s) / sPrecision_, v = double(t) / tPrecision_;
        vertices_.push_back(point(p, u, v));
        normals_.push_back(normal(p, u, v));
        patchUvs_.emplace_back(u, v);
      }
    for (uint32_t s = 0; s < static_cast<uint32_t>(sPrecision_); ++s)
      for (uint32_t t = 0; t < static_cast<uint32_t>(tPrecision_); ++t) {
        const uint32_t a = base + s * cols + t, b = a + cols, c = a + 1, d = b + 1;
        // (c - a) x (b - a) ~ dP/dt x dP/ds: the winding agrees with normal().
        triangles_.insert(triangles_.end(), {a, c, b, b, c, d});
      }
  }
  // One image over the whole surface (patches.c, set_texture_coordinates): s and t are x
  // and y across the tessellation's bounds, in the surface frame.
  glm::dvec2 lo(0), hi(0);
  for (size_t k = 0; k < vertices_.size(); ++k) {
    const glm::dvec2 xy(vertices_[k].x, vertices_[k].y);
    lo = k ? glm::min(lo, xy) : xy;
    hi = k ? glm::max(hi, xy) : xy;
  }
  const glm::dvec2 span = hi - lo;
  for (const DVec3& q : vertices_)
    surfaceUvs_.emplace_back(span.x > 0 ? (q.x - lo.x) / span.x : 0.0, span.y > 0 ? (q.y - lo.y) / span.y : 0.0);
}

CpfgSurface CpfgSurface::parse(const std::string& text, const std::string& fileName, double size, int sPrecision,
                               int tPrecision) {
  Tokens ts = tokenize(text, fileName);
  CpfgSurface f;
  f.file_ = fileName;
  if (!(size > 0)) size = 1.0;
  for (int k = 0; k < 6; ++k) ts.number("the header's bounds: xmin xmax ymin ymax zmin zmax");
  int fileS = kDefaultPrecision;
  if (!ts.done() && ts.peek().text == "PRECISION") {
    ++ts.next;
    ts.expect("S:", "the S precision");
    const Token at = ts.done() ? Token{} : ts.peek();
    fileS = ts.whole("the S precision");
    ts.expect("T:", "the T precision");
    ts.whole("the T precision");
    if (sPrecision == 0 && (fileS < 1 || fileS > kMaxPrecision))
      ts.fail(at.line, at.col, "a surface's precision is 1 to " + std::to_string(kMaxPrecision) + ", got " + std::to_string(fileS));
  }
  // cpfg (patches.c, determine_transform): without view file precisions, both are the
  // file's S precision.
  f.sPrecision_ = sPrecision > 0 ? sPrecision : fileS;
  f.tPrecision_ = tPrecision > 0 ? tPrecision : fileS;

  const DVec3 contact = ts.vector("CONTACT", "POINT", "the contact point");
  const DVec3 end = ts.vector("END", "POINT", "the end point");
  const size_t headingLine = ts.done() ? 0 : ts.peek().line, headingCol = ts.done() ? 0 : ts.peek().col;
  DVec3 heading = ts.vector("HEADING", nullptr, "the surface's heading");
  DVec3 up = ts.vector("UP", nullptr, "the surface's up vector");
  const size_t sizeLine = ts.done() ? 0 : ts.peek().line, sizeCol = ts.done() ? 0 : ts.peek().col;
  ts.expect("SIZE:", "the surface's size");
  const double fileSize = ts.number("the surface's size");
  if (!(fileSize > 0)) ts.fail(sizeLine, sizeCol, "the surface's SIZE must be greater than 0");
  if (glm::length(heading) == 0 || glm::length(up) == 0 || glm::length(glm::cross(heading, up)) < 1e-12 * glm::length(heading) * glm::length(up))
    ts.fail(headingLine, headingCol, "the surface's HEADING and UP must be nonzero and not parallel");
  heading = glm::normalize(heading);
  up = glm::normalize(up);
  const DVec3 left = glm::normalize(glm::cross(heading, up));
  up = glm::cross(left, heading);
  const double scale = size / fileSize;
  auto transform = [&](const DVec3& q) {
    const DVec3 v = (q - contact) * scale;
    return v.x * left + v.y * heading + v.z * up;
  };
  f.end_ = transform(end);

  struct Neighbours {
    Token names[8];
    Token self;
  };
  std::vector<Neighbours> neighbours;
  while (!ts.done()) {
    if (f.patches_.size() >= static_cast<size_t>(kMaxPatches))
      ts.fail(ts.peek().line, ts.peek().col, "a surface has at most " + std::to_string(kMaxPatches) + " patches (cpfg's limit)");
    Patch p;
    Neighbours nb;
    nb.self = ts.word("a patch name");
    p.name = nb.self.text;
    ts.expect("TOP", "the patch's colours");
    ts.expect("COLOR:", "the patch's top colour");
    ts.whole("the top colour index");
    ts.expect("DIFFUSE:", "the top diffuse coefficient");
    ts.number("the top diffuse coefficient");
    ts.expect("BOTTOM", "the patch's colours");
    ts.expect("COLOR:", "the patch's bottom colour");
    ts.whole("the bottom colour index");
    ts.expect("DIFFUSE:", "the bottom diffuse coefficient");
    ts.number("the bottom diffuse coefficient");
    for (int n = 0; n < 8; ++n) {
      ts.expect(kNeighbourKeys[n], "a neighbour of the patch");
      nb.names[n] = ts.word("a neighbour's name");
    }
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        DVec3 q;
        // cpfg reads the coordinates as floats.
        q.x = static_cast<float>(ts.number("a control point's x"));
        q.y = static_cast<float>(ts.number("a control point's y"));
        q.z = static_cast<float>(ts.number("a control point's z"));
        p.points[i][j] = transform(q);
      }
    f.patches_.push_back(std::move(p));
    neighbours.push_back(std::move(nb));
  }
  if (f.patches_.empty()) ts.failAtEnd("its first patch");
  // cpfg's check_connections: each neighbour names a patch of the file that names this one
  // back in the opposite direction.
  for (size_t p = 0; p < neighbours.size(); ++p)
    for (int n = 0; n < 8; ++n) {
      const Token& t = neighbours[p].names[n];
      if (t.text == "~") continue;
      size_t q = 0;
      while (q < f.patches_.size() && f.patches_[q].name != t.text) ++q;
      if (q == f.patches_.size())
        ts.fail(t.line, t.col, "no patch '" + t.text + "' in the file for patch '" + f.patches_[p].name + "''s " + kNeighbourKeys[n]);
      if (neighbours[q].names[7 - n].text != f.patches_[p].name)
        ts.fail(t.line, t.col, "patch '" + t.text + "' is '" + f.patches_[p].name + "''s " + kNeighbourKeys[n] + " but its " +
                                   kNeighbourKeys[7 - n] + " is '" + neighbours[q].names[7 - n].text + "'");
    }
  f.tessellate();
  return f;
}

}  // namespace sprig::lsystem
