#pragma once
/// cpfg's contour files (`.con`), which a view file names on its `contour: id FILE` lines and
/// a grammar selects with `@#(id)` as the cross-section of its generalized cylinders (CPFG
/// reference manual, "Generalized cylinders"; vlab's general.c, process_contour_file and
/// MakeContour, is the specification where the manual is silent).
///
/// Formats: the oldest, a first line `n dim closed|open` and n points of dim (2 or 3)
/// numbers; and `cver 1 1`, `cver 1 2`, `cver 1 3`: `name:`, `points: n total`, `type:`
/// (1 1: `open` or `closed`; 1 2 and 1 3: `o` or `c` then `r` regular, or `e`, which cpfg
/// reads as regular), for 1 3 a `samples:` line and optional background and `markers:`
/// lines, then n lines `x y z multiplicity` (the multiplicities summing to total).
///
/// The contour is the uniform cubic B-spline of its points (closed: wrapping around;
/// open: its num - 3 segments), resampled as cpfg does: lengths (in x and y) measured at 10
/// parameters per segment, `sides` points at equal length steps (parameters interpolated
/// linearly between the measured ones; an open contour's last point is the last measured
/// one, at parameter num - 3.1), and a closed contour rotated about z so that its point at
/// parameter 0 lies on +x. A closed contour's sides + 1-th point repeats the first.

#include <string>
#include <vector>

#include "core/types.h"

namespace sprig::lsystem {

class CpfgContour {
 public:
  /// The number of points around a cylinder without `contour sides:` (interpret.c) and
  /// cpfg's least.
  static constexpr int kDefaultSides = 8;
  static constexpr int kMinSides = 3;
  static constexpr int kMaxSides = 1024;

  CpfgContour() = default;

  /// cpfg's default contour (id 0): the unit circle, its point k at angle 2 pi k / sides.
  static CpfgContour circle();

  /// Reads a contour file's text (fileName for diagnostics). Throws InputError
  /// (`file:line:col`) for a malformed file, an unknown version, multiplicities that do not
  /// sum to the total, or fewer than 4 points (an open contour) or 3 (a closed one).
  static CpfgContour parse(const std::string& text, const std::string& fileName);

  /// The sides + 1 points around the contour (x, y and, for a 3-D contour, z).
  std::vector<DVec3> sample(int sides) const;

  bool closed() const { return closed_; }
  bool isCircle() const { return circle_; }
  const std::vector<DVec3>& points() const { return points_; }

  /// The spline point at parameter t (cpfg's evaluate_spline: indices wrap around).
  DVec3 at(double t) const;

 private:
  std::vector<DVec3> points_;
  bool closed_ = true;
  bool circle_ = false;
};

/// A contour of the view file with its id (`@#(id)`).
struct CpfgContourEntry {
  int id = 0;
  CpfgContour contour;
};

}  // namespace sprig::lsystem
