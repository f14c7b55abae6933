#include "lsystem/cpfg_function.h"

#include <algorithm>
#include <cstdio>

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/diagnostics.h"
#include "lsystem/detail/cpfg_text.h"

namespace sprig::lsystem {

namespace {

/// The lines of a function file with 1-based numbers, for positions in errors.
struct Lines {
  std::string file;
  std::vector<std::string> text;
  size_t next = 0;
  [[noreturn]] void fail(size_t line, size_t col, const std::string& msg) const {
    throw InputError(SourceLoc{file, static_cast<int>(line + 1), static_cast<int>(col + 1)}, msg,
                     line < text.size() ? text[line] : std::string());
  }
  bool done() const { return next >= text.size(); }
  const std::string& peek() const { return text[next]; }
  /// The next line, which must start with key (`points:`); returns the column after it.
  size_t expect(const std::string& key) {
    if (done()) fail(text.size() ? text.size() - 1 : 0, 0, "the function file ends before its '" + key + "' line");
    const std::string& s = text[next];
    size_t b = s.find_first_not_of(" \t");
    if (b == std::string::npos || s.compare(b, key.size(), key) != 0)
      fail(next, b == std::string::npos ? 0 : b, "expected '" + key + "' in a function file");
    ++next;
    return b + key.size();
  }
};

/// The numbers of line l from column c on; an unreadable one is an error at its column.
std::vector<double> numbers(const Lines& ls, size_t l, size_t c) {
  const std::string& s = ls.text[l];
  std::vector<double> out;
  size_t i = c;
  for (;;) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    if (i >= s.size()) return out;
    double v = 0;
    auto r = std::from_chars(s.data() + i, s.data() + s.size(), v);
    if (r.ec != std::errc() || !std::isfinite(v)) {
      size_t e = s.find_first_of(" \t", i);
      ls.fail(l, i, "expected a number, got '" + s.substr(i, e == std::string::npos ? std::string::npos : e - i) + "'");
    }
    out.push_back(v);
    i = static_cast<size_t>(r.ptr - s.data());
  }
}

}  // namespace

glm::dvec2 CpfgFunction::point(double d) const {
  const int n = static_cast<int>(points_.size()) - 1;
  const detail::ClampedBasis basis{n};
  const double u = d * (n - 2);
  glm::dvec2 sum(0.0);
  const int first = basis.first(u);
  for (int k = first; k <= std::min(n, first + 3); ++k) sum += points_[static_cast<size_t>(k)] * basis(k, 4, u);
  return sum;
}

double CpfgFunction::bisect(double x) const {
  double low = 0, high = 1;
  for (int it = 0; it < 200; ++it) {
    const double check = (low + high) / 2;
    const glm::dvec2 p = point(check);
    (p.x > x ? high : low) = check;
    if (std::fabs(p.x - x) <= 0.001) return p.y;
  }
  return std::nan("");
}

double CpfgFunction::value(double x) const {
  x = std::clamp(x, 0.0, 1.0);
  if (table_.empty()) return bisect(x);
  const double index = x * (samples_ - 1);
  const int i = static_cast<int>(std::floor(index));
  if (i >= samples_ - 1) return table_.back();
  const double w2 = index - i;
  return (1 - w2) * table_[static_cast<size_t>(i)] + w2 * table_[static_cast<size_t>(i) + 1];
}

CpfgFunction CpfgFunction::parse(const std::string& text, const std::string& fileName, int viewSamples) {
  Lines ls;
  ls.file = fileName;
  {
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      ls.text.push_back(line);
    }
  }
  CpfgFunction f;
  auto skipBlank = [&] {
    while (!ls.done() && ls.peek().find_first_not_of(" \t") == std::string::npos) ++ls.next;
  };
  auto startsWith = [&](const char* key) {
    if (ls.done()) return false;
    const std::string& s = ls.peek();
    size_t b = s.find_first_not_of(" \t");
    return b != std::string::npos && s.compare(b, std::string(key).size(), key) == 0;
  };
  skipBlank();
  bool oldFormat = false;
  if (startsWith("range:")) {
    // cpfg's first format: `range:` (read and ignored: the range is always [0, 1]).
    oldFormat = true;
    const size_t l = ls.next;
    const std::vector<double> r = numbers(ls, l, ls.expect("range:"));
    if (r.size() != 2) ls.fail(l, 0, "'range:' takes 2 numbers, got " + std::to_string(r.size()));
    f.samples_ = viewSamples;
  } else {
    const size_t l = ls.next;
    const std::vector<double> v = numbers(ls, l, ls.expect("fver"));
    if (v.size() != 2 || v[0] != 1 || v[1] != 1)
    {
      // %g, not a cast to int: the version may be any number (1e31 made the cast undefined).
      char version[64] = "?";
      if (v.size() == 2) std::snprintf(version, sizeof version, "%g.%g", v[0], v[1]);
      ls.fail(l, 0, std::string("function file version ") + version +
                        " is not supported (cpfg reads 'fver 1 1' and the 'range:' format)");
    }
    const size_t nc = ls.expect("name:");
    f.name_ = ls.text[ls.next - 1].substr(nc);
    f.name_.erase(0, f.name_.find_first_not_of(" \t"));
    const size_t sl = ls.next;
    const std::vector<double> s = numbers(ls, sl, ls.expect("samples:"));
    if (s.size() != 1 || s[0] != std::floor(s[0]) || s[0] < 0 || s[0] > 1e6)
      ls.fail(sl, 0, "'samples:' takes one whole number from 0 to 1000000");
    f.samples_ = static_cast<int>(s[0]);
    if (startsWith("b")) ls.next += 2;  // background image and its placement: not used
    if (startsWith("markers:")) {
      const size_t ml = ls.next;
      const std::vector<double> m = numbers(ls, ml, ls.expect("markers:"));
      if (m.size() != 1 || m[0] < 0 || m[0] != std::floor(m[0])) ls.fail(ml, 0, "'markers:' takes one whole number");
      // Compared as doubles first: a count past the file's end (1e105 once) is an error,
      // never a cast out of range.
      if (m[0] > double(ls.text.size() - ls.next))
        ls.fail(ml, 0, "'markers:' counts more lines than the file has after it");
      ls.next += static_cast<size_t>(m[0]);
    }
    ls.expect("flip:");
  }
  const size_t pl = ls.next;
  const std::vector<double> count = numbers(ls, pl, ls.expect("points:"));
  if (count.size() != 1 || count[0] != std::floor(count[0]) || count[0] < 4 || count[0] > 1e5)
    ls.fail(pl, 0, "a function needs at least 4 points ('points: n', n from 4 to 100000)");
  for (int k = 0; k < static_cast<int>(count[0]); ++k) {
    if (ls.done()) ls.fail(ls.text.size() - 1, 0, "the function file ends after " + std::to_string(k) + " of its " +
                                                      std::to_string(int(count[0])) + " points");
    const size_t l = ls.next++;
    const std::vector<double> p = numbers(ls, l, 0);
    const size_t most = oldFormat ? 2 : 3;
    if (p.size() < 2 || p.size() > most)
      ls.fail(l, 0, std::string("a point is 'x y'") + (oldFormat ? "" : " or 'x y multiplicity'") + ", got " +
                        std::to_string(p.size()) + " number(s)");
    int mult = 1;
    if (p.size() == 3) {
      if (p[2] < 1 || p[2] > 4 || p[2] != std::floor(p[2])) ls.fail(l, 0, "a point's multiplicity is 1 to 4");
      mult = static_cast<int>(p[2]);
    }
    // cpfg reads the coordinates as floats.
    const glm::dvec2 q(static_cast<float>(p[0]), static_cast<float>(p[1]));
    for (int m = 0; m < mult; ++m) f.points_.push_back(q);
  }
  // x must increase along the curve for func(n, x) to be a function of x.
  for (int i = 0; i <= 64; ++i) {
    const double x = i / 64.0;
    if (std::isnan(f.bisect(x)))
      ls.fail(pl, 0, "the function's x does not increase from 0 to 1 along its curve (no point with x = " + std::to_string(x) + ")");
  }
  if (f.samples_ > 2) {
    f.table_.resize(static_cast<size_t>(f.samples_));
    for (int i = 0; i < f.samples_; ++i) f.table_[static_cast<size_t>(i)] = f.bisect(double(i) / double(f.samples_ - 1));
  }
  return f;
}

}  // namespace sprig::lsystem
