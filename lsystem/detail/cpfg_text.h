#pragma once
/// Pieces shared by the readers of cpfg's data files (function, curve and contour files):
/// the words of a line with their columns, and cpfg's clamped B-spline basis.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace sprig::lsystem::detail {

/// A word of a line with its 0-based column.
struct Word {
  std::string text;
  size_t col;
};

/// The words of s from column `from` on, separated by spaces, tabs and carriage returns.
inline std::vector<Word> wordsOf(const std::string& s, size_t from = 0) {
  std::vector<Word> out;
  size_t i = from;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    if (i >= s.size()) break;
    size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    out.push_back({s.substr(i, j - i), i});
    i = j;
  }
  return out;
}

/// Cox-de Boor basis N_{k,t}(u) over cpfg's clamped integer knots for n + 1 points (as
/// cpfg's splinefun.cpp and curveXYZ.cpp build them): knot j is 0 below 4, n - 2 above n,
/// else j - 3; half-open intervals.
struct ClampedBasis {
  int n;
  int knot(int j) const { return j < 4 ? 0 : j > n ? n - 2 : j - 3; }
  /// The first k whose N_{k,4}(u) may be nonzero: only k to k + 3 are (at u in [m, m + 1),
  /// points m to m + 3), so an evaluation costs 4 basis functions, not n + 1.
  int first(double u) const {
    const double m = std::floor(u);
    return m <= 0 || !(m == m) ? 0 : m >= n - 3 ? std::max(n - 3, 0) : static_cast<int>(m);
  }
  double operator()(int k, int t, double u) const {
    if (t == 1) return knot(k) <= u && u < knot(k + 1) ? 1.0 : 0.0;
    double sum = 0;
    if (int d = knot(k + t - 1) - knot(k)) sum = (u - knot(k)) / d * (*this)(k, t - 1, u);
    if (int d = knot(k + t) - knot(k + 1)) sum += (knot(k + t) - u) / d * (*this)(k + 1, t - 1, u);
    return sum;
  }
};

}  // namespace sprig::lsystem::detail
