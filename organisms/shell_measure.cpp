#include "organisms/shell_measure.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace sprig::organisms {

namespace {

/// Last inside→outside crossing of the 0.5 iso surface from `from` along unit `dir` within
/// [0, maxT] (grid of `steps`, refined by bisection); negative when none.
double lastExit(const blobtree::CompiledBlob& b, const DVec3& from, const DVec3& dir, double maxT, int steps) {
  double last = -1.0;
  auto inside = [&](double t) { return b.value(Vec3(from + t * dir)) > 0.5f; };
  bool prev = inside(0.0);
  for (int i = 1; i <= steps; ++i) {
    const double t = maxT * i / steps;
    const bool in = inside(t);
    if (prev && !in) {
      double lo = maxT * (i - 1) / steps, hi = t;
      for (int k = 0; k < 40; ++k) {
        const double mid = 0.5 * (lo + hi);
        (inside(mid) ? lo : hi) = mid;
      }
      last = 0.5 * (lo + hi);
    }
    prev = in;
  }
  return last;
}

/// First outside→inside crossing from `from` along `dir` within [0, maxT]; negative when none.
double firstEntry(const blobtree::CompiledBlob& b, const DVec3& from, const DVec3& dir, double maxT, int steps) {
  auto inside = [&](double t) { return b.value(Vec3(from + t * dir)) > 0.5f; };
  if (inside(0.0)) return 0.0;
  for (int i = 1; i <= steps; ++i) {
    const double t = maxT * i / steps;
    if (!inside(t)) continue;
    double lo = maxT * (i - 1) / steps, hi = t;
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (lo + hi);
      (inside(mid) ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  }
  return -1.0;
}

}  // namespace

ShellMeasures measureShell(const ShellParams& p, const ShellModel& m, const blobtree::CompiledBlob& b) {
  ShellMeasures out;
  const HelicoSpiral& s = m.spiral;
  const double te = m.endDeg;
  const double he = s.height(te), de = s.curveSize(te);
  out.apertureBaseY = he + de;
  out.sutureY = he - de * std::cos(radians(s.betaDeg));
  // Apex: down the first whorl's line parallel to the axis, from well above it.
  {
    const DVec3 c = s.point(p.startDeg);
    const double d0 = s.curveSize(p.startDeg);
    const DVec3 from = c - DVec3(0.0, 4.0 * d0 + 0.01, 0.0);
    const double t = firstEntry(b, from, DVec3(0, 1, 0), 8.0 * d0 + 0.02, 4000);
    out.apexY = t >= 0.0 ? from.y + t : c.y - d0;
  }
  // Canal tip: the farthest exit along lines parallel to the axis around the newest canal
  // copy's tip (the tube may be hollow, so its centre line alone can miss the wall).
  out.canalTipY = out.apertureBaseY;
  if (p.canal) {
    const GeneratingPrimitive g = p.canal->primitives(s).back();
    const glm::dmat4 frame = s.shellFromGenerating(te);  // the canal hangs unshifted from the spiral
    const DVec3 tip(frame * glm::dvec4(DVec3(g.b), 1.0));
    const double r = 1.5 * g.radiusB * m.sizeCalibration * de;
    const double start = std::min(out.apertureBaseY, tip.y - 4.0 * r);
    const double reach = tip.y + 6.0 * r - start;
    for (int ring = 0; ring <= 4; ++ring)
      for (int k = 0; k < (ring == 0 ? 1 : 12); ++k) {
        const double a = 2.0 * kPi * k / 12.0, rr = r * ring / 4.0;
        const DVec3 from(tip.x + rr * std::cos(a), start, tip.z + rr * std::sin(a));
        const double t = lastExit(b, from, DVec3(0, 1, 0), reach, 1500);
        if (t >= 0.0) out.canalTipY = std::max(out.canalTipY, start + t);
      }
  }
  out.restLength = out.apertureBaseY - out.apexY;
  out.bodyWhorlLength = out.apertureBaseY - out.sutureY;
  out.canalLength = out.canalTipY - out.apertureBaseY;
  out.totalLength = out.canalTipY - out.apexY;
  // Aperture: the hollow around the generating centre 10° inside the lip, along the axis
  // and across; zero when the centre is solid (no opening).
  {
    const double th = te - 10.0;
    const DVec3 c = s.point(th);
    const double d = s.curveSize(th);
    if (b.value(Vec3(c)) < 0.5f) {
      const DVec3 e = glm::normalize(DVec3(c.x, 0.0, c.z));
      auto reach = [&](const DVec3& dir) {
        const double t = firstEntry(b, c, dir, 3.0 * d, 3000);
        return t < 0.0 ? 3.0 * d : t;
      };
      out.apertureHeight = reach(DVec3(0, 1, 0)) + reach(DVec3(0, -1, 0));
      out.apertureWidth = reach(e) + reach(-e);
    }
  }
  for (const SpineRecord& r : m.spines) {
    if (r.part == ShellPart::VarixSpine) {
      ++out.varixSpines;
      out.longestVarixSpine = std::max(out.longestVarixSpine, static_cast<double>(r.lengthShell));
    } else {
      ++out.axialSpines;
      out.longestAxialSpine = std::max(out.longestAxialSpine, static_cast<double>(r.lengthShell));
    }
  }
  return out;
}

}  // namespace sprig::organisms
