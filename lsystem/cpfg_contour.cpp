#include "lsystem/cpfg_contour.h"

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/diagnostics.h"
#include "lsystem/detail/cpfg_text.h"

namespace sprig::lsystem {

namespace {

using detail::Word;
using detail::wordsOf;

/// The lines of a contour file and a reader over them, with positions for errors.
struct Reader {
  std::string file;
  std::vector<std::string> lines;
  size_t next = 0;

  [[noreturn]] void fail(size_t line, size_t col, const std::string& msg) const {
    throw InputError(SourceLoc{file, static_cast<int>(line + 1), static_cast<int>(col + 1)}, msg,
                     line < lines.size() ? lines[line] : std::string());
  }
  /// The next line that is not blank; an error at the end of the file.
  size_t line(const std::string& what) {
    while (next < lines.size() && wordsOf(lines[next]).empty()) ++next;
    if (next >= lines.size()) {
      const size_t l = lines.empty() ? 0 : lines.size() - 1;
      fail(l, 0, "the contour file ends before " + what);
    }
    return next++;
  }
  double number(size_t l, const Word& w, const char* what) const {
    double v = 0;
    auto r = std::from_chars(w.text.data(), w.text.data() + w.text.size(), v);
    if (r.ec != std::errc() || r.ptr != w.text.data() + w.text.size() || !std::isfinite(v))
      fail(l, w.col, std::string("expected a number (") + what + "), got '" + w.text + "'");
    return v;
  }
  int whole(size_t l, const Word& w, const char* what, int lo, int hi) const {
    const double v = number(l, w, what);
    if (v != std::floor(v) || v < lo || v > hi)
      fail(l, w.col, std::string(what) + " is a whole number from " + std::to_string(lo) + " to " + std::to_string(hi) + ", got '" + w.text + "'");
    return static_cast<int>(v);
  }
  /// A line `key value...`: its words after the key.
  std::vector<Word> keyed(const char* key) {
    const size_t l = line(std::string("its '") + key + "' line");
    std::vector<Word> w = wordsOf(lines[l]);
    if (w.empty() || w[0].text != key) fail(l, w.empty() ? 0 : w[0].col, std::string("expected '") + key + "' in a contour file");
    w.erase(w.begin());
    lastLine = l;
    return w;
  }
  size_t lastLine = 0;
};

}  // namespace

CpfgContour CpfgContour::circle() {
  CpfgContour c;
  c.circle_ = true;
  c.closed_ = true;
  return c;
}

DVec3 CpfgContour::at(double t) const {
  const size_t num = points_.size();
  const double first = std::floor(t);
  const double x = t - first, x2 = x * x, x3 = x2 * x;
  const double w[4] = {(1 - x) * (1 - x) * (1 - x) / 6, (3 * x3 - 6 * x2 + 4) / 6, (-3 * x3 + 3 * x2 + 3 * x + 1) / 6, x3 / 6};
  size_t k = static_cast<size_t>(first) % num;
  DVec3 sum(0.0);
  for (int i = 0; i < 4; ++i) {
    sum += w[i] * points_[k];
    k = k + 1 == num ? 0 : k + 1;
  }
  return sum;
}

std::vector<DVec3> CpfgContour::sample(int sides) const {
  std::vector<DVec3> out(static_cast<size_t>(sides) + 1);
  if (circle_) {
    for (int i = 0; i < sides; ++i) {
      const double a = 2 * kPi * i / sides;
      out[static_cast<size_t>(i)] = DVec3(std::cos(a), std::sin(a), 0);
    }
    out[static_cast<size_t>(sides)] = out[0];
    return out;
  }
  constexpr int n = 10;  // lengths measured per unit of the parameter
  const int num = static_cast<int>(points_.size());
  const int segments = closed_ ? num : num - 3;
  std::vector<double> lengths(static_cast<size_t>(segments * n));
  auto xyDistance = [](const DVec3& a, const DVec3& b) { return std::hypot(a.x - b.x, a.y - b.y); };
  DVec3 last = at(0.0);
  double total = 0;
  for (int i = 0; i < segments; ++i)
    for (int j = 0; j < n; ++j) {
      const DVec3 p = at(i + double(j) / n);
      total += xyDistance(last, p);
      lengths[static_cast<size_t>(i * n + j)] = total;
      last = p;
    }
  double c = 1, s = 0;  // rotation taking the point at 0 onto +x (closed contours)
  if (closed_) {
    const DVec3 p0 = at(0.0);
    total += xyDistance(last, p0);
    const double len = std::hypot(p0.x, p0.y);
    if (len * len >= 1e-9) {
      c = p0.x / len;
      s = p0.y / len;
    }
  }
  double extent = 0;
  for (const DVec3& p : points_) extent = std::max(extent, std::hypot(p.x - points_[0].x, p.y - points_[0].y));
  if (!(total > 1e-9 * extent) || extent == 0) {
    for (DVec3& p : out) p = DVec3(std::nan(""));
    return out;
  }
  const double step = total / sides;
  const int count = closed_ ? sides : sides + 1;
  const size_t lastIndex = lengths.size() - 1;
  size_t j = 0;
  for (int i = 0; i < count; ++i) {
    const double want = i * step;
    double t = 0;
    if (i > 0) {
      while (lengths[j] < want && j < lastIndex) ++j;
      if (j == 0) j = 1;
      size_t j2 = j - 1;
      while (j2 > 0 && lengths[j] - lengths[j2] <= 1e-10 / step) --j2;
      t = double(j2) / n + (want - lengths[j2]) / (lengths[j] - lengths[j2]) / n;
    }
    const DVec3 p = at(t);
    out[static_cast<size_t>(i)] = DVec3(p.x * c + p.y * s, -p.x * s + p.y * c, p.z);
  }
  if (closed_) out[static_cast<size_t>(sides)] = out[0];
  return out;
}

CpfgContour CpfgContour::parse(const std::string& text, const std::string& fileName) {
  Reader r;
  r.file = fileName;
  {
    std::istringstream in(text);
    std::string l;
    while (std::getline(in, l)) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      r.lines.push_back(l);
    }
  }
  CpfgContour c;
  const size_t first = r.line("its first line");
  const std::vector<Word> head = wordsOf(r.lines[first]);
  if (head[0].text == "cver") {
    if (head.size() != 3) r.fail(first, head[0].col, "expected 'cver 1 1', 'cver 1 2' or 'cver 1 3'");
    const int major = r.whole(first, head[1], "the version", 0, 1000), minor = r.whole(first, head[2], "the version", 0, 1000);
    if (major != 1 || minor < 1 || minor > 3)
      r.fail(first, head[1].col, "contour file version " + std::to_string(major) + "." + std::to_string(minor) +
                                     " is not supported (cpfg reads 'cver 1 1' to 'cver 1 3' and the older 'n dim closed|open')");
    r.keyed("name:");
    std::vector<Word> pts = r.keyed("points:");
    const size_t pointsLine = r.lastLine;
    if (pts.size() != 2) r.fail(pointsLine, 0, "'points:' takes 2 numbers: the points in the file and the total with multiplicities");
    const int listed = r.whole(pointsLine, pts[0], "the number of points", 1, 100000);
    const int total = r.whole(pointsLine, pts[1], "the total number of points", 1, 100000);
    std::vector<Word> type = r.keyed("type:");
    if (type.size() != 1) r.fail(r.lastLine, 0, "'type:' takes one word");
    const std::string& t = type[0].text;
    if (minor == 1) {
      c.closed_ = t.rfind("open", 0) != 0;
    } else {
      if (t.size() < 2 || (t[0] != 'o' && t[0] != 'c') || (t[1] != 'r' && t[1] != 'e'))
        r.fail(r.lastLine, type[0].col, "a contour's type is 'o' (open) or 'c' (closed) then 'r' (regular) or 'e', got '" + t + "'");
      c.closed_ = t[0] == 'c';
    }
    if (minor == 3) {
      r.keyed("samples:");
      while (r.next < r.lines.size() && !wordsOf(r.lines[r.next]).empty() && r.lines[r.next].find_first_not_of(" \t") != std::string::npos &&
             r.lines[r.next][r.lines[r.next].find_first_not_of(" \t")] == 'b')
        r.next += 2;  // a background image and its placement: not used
      if (r.next < r.lines.size() && r.lines[r.next].find("markers:") != std::string::npos) {
        std::vector<Word> m = r.keyed("markers:");
        if (m.size() != 1) r.fail(r.lastLine, 0, "'markers:' takes one whole number");
        const int markers = r.whole(r.lastLine, m[0], "the number of markers", 0, static_cast<int>(r.lines.size()));
        r.next += static_cast<size_t>(markers);
      }
    }
    for (int i = 0; i < listed; ++i) {
      const size_t l = r.line("point " + std::to_string(i + 1) + " of its " + std::to_string(listed));
      const std::vector<Word> w = wordsOf(r.lines[l]);
      if (w.size() != 4) r.fail(l, w[0].col, "a contour point is 'x y z multiplicity', got " + std::to_string(w.size()) + " number(s)");
      DVec3 p;
      for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(r.number(l, w[static_cast<size_t>(k)], "a coordinate"));
      const int m = r.whole(l, w[3], "a point's multiplicity", 0, 100);
      for (int k = 0; k < m; ++k) c.points_.push_back(p);
    }
    if (static_cast<int>(c.points_.size()) != total)
      r.fail(pointsLine, pts[1].col, "'points: " + std::to_string(listed) + " " + std::to_string(total) + "' but the multiplicities sum to " +
                                         std::to_string(c.points_.size()));
  } else {
    // cpfg's oldest format: `n dim closed|open`.
    if (head.size() != 3) r.fail(first, head[0].col, "expected 'cver 1 3' or 'n dim closed|open' on a contour file's first line");
    const int n = r.whole(first, head[0], "the number of points", 1, 100000);
    const int dim = r.whole(first, head[1], "the dimension", 2, 3);
    c.closed_ = head[2].text == "closed";
    for (int i = 0; i < n; ++i) {
      const size_t l = r.line("point " + std::to_string(i + 1) + " of its " + std::to_string(n));
      const std::vector<Word> w = wordsOf(r.lines[l]);
      if (static_cast<int>(w.size()) != dim)
        r.fail(l, w[0].col, "a contour point has " + std::to_string(dim) + " numbers (the dimension), got " + std::to_string(w.size()));
      DVec3 p(0.0);
      for (int k = 0; k < dim; ++k) p[k] = static_cast<float>(r.number(l, w[static_cast<size_t>(k)], "a coordinate"));
      c.points_.push_back(p);
    }
  }
  while (r.next < r.lines.size() && wordsOf(r.lines[r.next]).empty()) ++r.next;
  if (r.next < r.lines.size()) r.fail(r.next, 0, "unexpected line after the contour's points");
  const size_t least = c.closed_ ? 3 : 4;
  if (c.points_.size() < least)
    r.fail(first, 0, std::string("a") + (c.closed_ ? " closed" : "n open") + " contour needs at least " + std::to_string(least) +
                         " points (counting multiplicities), got " + std::to_string(c.points_.size()));
  // The contour must have a length for its points to be spaced along it.
  const std::vector<DVec3> probe = c.sample(kMinSides);
  for (const DVec3& p : probe)
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) r.fail(first, 0, "the contour has length 0 (all its points coincide)");
  return c;
}

}  // namespace sprig::lsystem
