#pragma once
/// cpfg's graphically defined functions: the function files (`.func`) a view file names on
/// its `function:` lines, which a grammar reads with `func(n, x)` (CPFG reference manual,
/// section 5.5; vlab's splinefun.cpp is the specification where the manual is silent).
///
/// A function is a cubic B-spline over its control points (x, y) with clamped integer
/// knots (n + 1 points: knots 0,0,0,0,1,...,n-2,n-2,n-2,n-2; four points make a Bezier
/// segment). func(n, x) is y at the curve point whose x is within 0.001 of the argument,
/// found by bisection on the curve parameter (the argument clamped to [0, 1]); with more
/// than 2 samples, y is precomputed that way at samples evenly spaced x and interpolated
/// linearly between them, as cpfg does.

#include <string>
#include <vector>

#include "core/types.h"

namespace sprig::lsystem {

/// One function file, read and ready to evaluate.
class CpfgFunction {
 public:
  CpfgFunction() = default;

  /// The curve point at parameter d in [0, 1] (cpfg's SplineFunction::P; at d = 1 exactly,
  /// cpfg's half-open basis gives (0, 0), which bisection never reaches).
  glm::dvec2 point(double d) const;
  /// func(n, x): see the file comment. NaN when bisection does not converge in 200 halvings
  /// (x not increasing along the curve).
  double value(double x) const;

  const std::string& name() const { return name_; }
  const std::vector<glm::dvec2>& points() const { return points_; }
  int samples() const { return samples_; }

  /// Reads a function file's text (fileName for diagnostics): cpfg's two formats,
  /// `range: a b` / `points: n` / n lines `x y` (samples then come from the view file's
  /// `function:` line, viewSamples; -1 when it gives none), and `fver 1 1` / `name:` /
  /// `samples:` / optional background and `markers:` lines / `flip:` / `points: n` / n lines
  /// `x y [multiplicity]`. Throws InputError (`file:line:col`) for a malformed file, fewer
  /// than 4 points, or x not increasing along the curve.
  static CpfgFunction parse(const std::string& text, const std::string& fileName, int viewSamples);

 private:
  double bisect(double x) const;

  std::string name_;
  std::vector<glm::dvec2> points_;
  int samples_ = 0;
  std::vector<double> table_;  ///< precomputed values at i / (samples - 1), when samples > 2
};

}  // namespace sprig::lsystem
