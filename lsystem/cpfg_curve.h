#pragma once
/// cpfg's curve files, which a view file names on its `curve: FILE [samples]` lines and a
/// grammar reads with `curveX(n, t)`, `curveY(n, t)`, `curveZ(n, t)` and `curveGAL(n)`
/// (CPFG reference manual, "curve"; vlab's curveXYZ.cpp and curveXYZc.cpp are the
/// specification where the manual is silent).
///
/// The file is a list of lines: `version:`, `contact:`, `end:`, `heading:`, `up:`, `size:`,
/// `range:` (read, not used by these functions), `points: n`, `dimension: d` (or `dim:`;
/// default 2), `type: bspline | bspline-closed | bspline-endpoint | bspline-phantom |
/// bezier`, then n point lines of d numbers `x y [z [multiplicity]]`; `//` starts a comment
/// line. The curve is evaluated as cpfg does: a point of multiplicity m counts m times; a
/// uniform cubic B-spline (`bspline`; `bspline-closed` repeats the first three points after
/// the last; `bspline-phantom` adds the reflections 2 p1 - p2 before the first and after
/// the last), a clamped one (`bspline-endpoint`), or consecutive cubic Bezier segments
/// (`bezier`, 3k + 1 points). curveX(n, t) is x at arc length t (t clamped to [0, 1]) of
/// the curve's polyline through `samples` points at evenly spaced parameters (default 100),
/// interpolated linearly between them; curveGAL(n) is that polyline's length.

#include <string>
#include <vector>

#include "core/types.h"

namespace sprig::lsystem {

class CpfgCurve {
 public:
  enum class Type { BSpline, BSplineClosed, BSplineEndpoint, BSplinePhantom, Bezier };

  /// Default samples when the `curve:` line gives none (interpret.c).
  static constexpr int kDefaultSamples = 100;

  CpfgCurve() = default;

  /// The curve point at parameter u in [0, 1] (curveXYZ.cpp, calcPValue).
  DVec3 point(double u) const;
  /// The point at normalized arc length t (t clamped to [0, 1]): curveX/Y/Z.
  DVec3 atLength(double t) const;
  /// curveGAL: the length of the sampled polyline.
  double length() const { return length_; }

  Type type() const { return type_; }
  /// The control points with multiplicities expanded (and closing or phantom points added).
  const std::vector<DVec3>& points() const { return points_; }

  /// Reads a curve file's text (fileName for diagnostics) sampled at samples points (at
  /// least 2). Throws InputError (`file:line:col`) for an unknown line, a malformed number,
  /// a point line whose count is not the dimension, a count of points that is not the
  /// `points:` line's, fewer than 4 points after multiplicities, a Bezier curve whose count
  /// is not 3k + 1, a second `points:` line (cpfg's nested curves) or a `bezier-surface`.
  static CpfgCurve parse(const std::string& text, const std::string& fileName, int samples);

 private:
  /// The closed curve's first three points again at its end, or the phantom curve's two
  /// mirrored end points (cpfg's bspline-closed and bspline-phantom).
  void addEndPoints();
  /// Fills lengths_ with the cumulative chord lengths at `samples` (>= 2) equal steps of the
  /// parameter (not yet normalized); returns the total.
  double tabulateLengths(int samples);

  std::vector<DVec3> points_;
  Type type_ = Type::BSpline;
  std::vector<double> lengths_;  ///< normalized cumulative lengths at the samples
  double length_ = 0;
};

}  // namespace sprig::lsystem
