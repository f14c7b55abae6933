#include "lsystem/cpfg_curve.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "core/diagnostics.h"
#include "lsystem/detail/cpfg_text.h"

namespace sprig::lsystem {

namespace {

using detail::ClampedBasis;
using detail::Word;
using detail::wordsOf;

}  // namespace

DVec3 CpfgCurve::point(double u) const {
  const int n = static_cast<int>(points_.size());
  if (type_ == Type::BSplineEndpoint) {
    const ClampedBasis basis{n - 1};
    const double t = u * (n - 3.000001);
    DVec3 sum(0.0);
    const int first = basis.first(t);
    for (int k = first; k < std::min(n, first + 4); ++k) sum += points_[static_cast<size_t>(k)] * basis(k, 4, t);
    return sum;
  }
  if (type_ == Type::Bezier) {
    const int segments = 1 + (n - 4) / 3;
    const int c = static_cast<int>(u / (1.000001 / segments));
    const double t = (u - c * (1.0 / segments)) * segments / 1.000001;
    const double v = 1 - t;
    const size_t i = static_cast<size_t>(3 * c);
    return v * v * v * points_[i] + 3 * t * v * v * points_[i + 1] + 3 * t * t * v * points_[i + 2] + t * t * t * points_[i + 3];
  }
  // Uniform cubic B-spline over integer knots: the segment of points i - 3 .. i.
  const double y = u * (n - 3.000001);
  const double f = std::floor(y);
  const size_t i = 3 + static_cast<size_t>(f);
  const double x = y - f, x2 = x * x, x3 = x2 * x;
  return ((1 - x) * (1 - x) * (1 - x) * points_[i - 3] + (3 * x3 - 6 * x2 + 4) * points_[i - 2] +
          (-3 * x3 + 3 * x2 + 3 * x + 1) * points_[i - 1] + x3 * points_[i]) /
         6.0;
}

DVec3 CpfgCurve::atLength(double t) const {
  t = std::clamp(t, 0.0, 1.0);
  const size_t samples = lengths_.size();
  size_t lo = 0, hi = samples - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    (lengths_[mid] > t ? hi : lo) = mid;
  }
  const double span = lengths_[hi] - lengths_[lo];
  const double u = (static_cast<double>(lo) + (span > 0 ? (t - lengths_[lo]) / span : 0.0)) / static_cast<double>(samples - 1);
  return point(u);
}

void CpfgCurve::addEndPoints() {
  if (type_ == Type::BSplineClosed)
    for (size_t k = 0; k < 3; ++k) points_.push_back(points_[k]);
  if (type_ == Type::BSplinePhantom) {
    const size_t n = points_.size();
    const DVec3 first = 2.0 * points_[0] - points_[1], last = 2.0 * points_[n - 1] - points_[n - 2];
    points_.insert(points_.begin(), first);
    points_.push_back(last);
  }
}

double CpfgCurve::tabulateLengths(int samples) {
  lengths_.assign(static_cast<size_t>(samples), 0.0);
  DVec3 prev = point(0.0);
  double total = 0;
  for (int i = 1; i < samples; ++i) {
    const DVec3 p = point(i / double(samples - 1));
    total += glm::length(p - prev);
    lengths_[static_cast<size_t>(i)] = total;
    prev = p;
  }
  return total;
}

CpfgCurve CpfgCurve::parse(const std::string& text, const std::string& fileName, int samples) {
  std::vector<std::string> lines;
  {
    std::istringstream in(text);
    std::string l;
    while (std::getline(in, l)) {
      if (!l.empty() && l.back() == '\r') l.pop_back();
      lines.push_back(l);
    }
  }
  auto fail = [&](size_t line, size_t col, const std::string& msg) {
    throw InputError(SourceLoc{fileName, static_cast<int>(line + 1), static_cast<int>(col + 1)}, msg,
                     line < lines.size() ? lines[line] : std::string());
  };
  auto number = [&](size_t line, const Word& w, const char* what) {
    double v = 0;
    auto r = std::from_chars(w.text.data(), w.text.data() + w.text.size(), v);
    if (r.ec != std::errc() || r.ptr != w.text.data() + w.text.size() || !std::isfinite(v))
      fail(line, w.col, std::string("expected a number (") + what + "), got '" + w.text + "'");
    return v;
  };
  CpfgCurve c;
  int count = -1, dim = 2;
  size_t pointsLine = 0, read = 0;
  struct Keyed {
    const char* key;
    int numbers;  ///< numbers after it; -1 for one word
  };
  static constexpr Keyed kKeys[] = {{"version:", -1}, {"contact:", 3}, {"end:", 3},   {"heading:", 3},
                                    {"up:", 3},       {"size:", 1},    {"range:", 2}};
  for (size_t l = 0; l < lines.size(); ++l) {
    const std::string& s = lines[l];
    const size_t b = s.find_first_not_of(" \t\r");
    if (b == std::string::npos || s.compare(b, 2, "//") == 0) continue;
    auto is = [&](const char* key) { return s.compare(b, std::string(key).size(), key) == 0; };
    auto after = [&](const char* key) { return wordsOf(s, b + std::string(key).size()); };
    bool known = false;
    for (const Keyed& k : kKeys)
      if (is(k.key)) {
        known = true;
        const std::vector<Word> w = after(k.key);
        const size_t want = k.numbers < 0 ? 1 : static_cast<size_t>(k.numbers);
        if (w.size() != want)
          fail(l, b, std::string("'") + k.key + "' takes " + std::to_string(want) + (k.numbers < 0 ? " word" : " number(s)") +
                         ", got " + std::to_string(w.size()));
        if (k.numbers > 0)
          for (const Word& x : w) number(l, x, k.key);
      }
    if (known) continue;
    if (is("points:")) {
      if (count >= 0) fail(l, b, "a second 'points:' line (cpfg's nested curves) is not supported");
      const std::vector<Word> w = after("points:");
      if (w.size() != 1) fail(l, b, "'points:' takes one whole number");
      const double v = number(l, w[0], "the number of points");
      if (v != std::floor(v) || v < 1 || v > 100000) fail(l, w[0].col, "'points:' is a whole number from 1 to 100000");
      count = static_cast<int>(v);
      pointsLine = l;
      continue;
    }
    if (is("dimension:") || is("dim:")) {
      const char* key = is("dim:") ? "dim:" : "dimension:";
      if (count < 0) fail(l, b, std::string("'") + key + "' must follow the 'points:' line");
      const std::vector<Word> w = after(key);
      if (w.size() != 1) fail(l, b, std::string("'") + key + "' takes one whole number");
      const double v = number(l, w[0], "the dimension");
      if (v != 2 && v != 3 && v != 4) fail(l, w[0].col, "the dimension is 2 (x y), 3 (x y z) or 4 (x y z multiplicity)");
      dim = static_cast<int>(v);
      continue;
    }
    if (is("type:")) {
      if (count < 0) fail(l, b, "'type:' must follow the 'points:' line");
      const std::vector<Word> w = after("type:");
      if (w.size() != 1) fail(l, b, "'type:' takes one word");
      const std::string& t = w[0].text;
      if (t == "bezier-surface") fail(l, w[0].col, "cpfg's curve type 'bezier-surface' is not supported");
      c.type_ = t == "bezier"              ? Type::Bezier
                : t == "bspline-phantom"   ? Type::BSplinePhantom
                : t == "bspline-endpoint"  ? Type::BSplineEndpoint
                : t == "bspline-closed"    ? Type::BSplineClosed
                : t == "bspline"           ? Type::BSpline
                                           : (fail(l, w[0].col, "unknown curve type '" + t + "' (bspline, bspline-closed, bspline-endpoint, bspline-phantom or bezier)"), Type::BSpline);
      continue;
    }
    if (s.find(':') != std::string::npos) fail(l, b, "unknown line in a curve file: '" + s.substr(b) + "'");
    // A control point.
    if (count < 0) fail(l, b, "a control point before the 'points:' line");
    const std::vector<Word> w = wordsOf(s, b);
    if (static_cast<int>(w.size()) != dim)
      fail(l, b, "a control point has " + std::to_string(dim) + " numbers (the dimension), got " + std::to_string(w.size()));
    if (static_cast<int>(read) >= count) fail(l, b, "more control points than 'points: " + std::to_string(count) + "'");
    DVec3 p(0.0);
    for (int k = 0; k < std::min(dim, 3); ++k) p[k] = static_cast<float>(number(l, w[static_cast<size_t>(k)], "a coordinate"));
    int mult = 1;
    if (dim == 4) {
      const double m = number(l, w[3], "a multiplicity");
      if (m != std::floor(m) || m < 0 || m > 100) fail(l, w[3].col, "a point's multiplicity is a whole number from 0 to 100");
      mult = static_cast<int>(m);
    }
    for (int k = 0; k < mult; ++k) c.points_.push_back(p);
    ++read;
  }
  if (count < 0) fail(lines.empty() ? 0 : lines.size() - 1, 0, "the curve file has no 'points:' line");
  if (static_cast<int>(read) != count)
    fail(pointsLine, 0, "'points: " + std::to_string(count) + "' but the file has " + std::to_string(read) + " control point(s)");
  if (c.points_.size() < 4) fail(pointsLine, 0, "a curve needs at least 4 control points (counting multiplicities)");
  if (c.type_ == Type::Bezier && (c.points_.size() - 1) % 3 != 0)
    fail(pointsLine, 0, "a Bezier curve has 3k + 1 control points (counting multiplicities), got " + std::to_string(c.points_.size()));
  c.addEndPoints();
  const double total = c.tabulateLengths(samples < 2 ? kDefaultSamples : samples);
  double extent = 0;
  for (const DVec3& p : c.points_) extent = std::max(extent, glm::length(p - c.points_[0]));
  if (!(total > 1e-9 * extent) || extent == 0) fail(pointsLine, 0, "the curve has length 0 (all its points coincide)");
  for (double& x : c.lengths_) x /= total;
  c.length_ = total;
  return c;
}

}  // namespace sprig::lsystem
