#include <catch2/catch.hpp>

#include <cmath>

#include "blobtree/compiled.h"
#include "organisms/shell.h"
#include "organisms/shell_paint.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {

/// First crossing of the 0.5 iso surface from `from` along `dir` (outside→inside when the
/// start is outside, and the reverse when inside), refined by bisection.
DVec3 crossing(const blobtree::CompiledBlob& b, const DVec3& from, const DVec3& dir, double maxT) {
  const bool start = b.value(Vec3(from)) > 0.5f;
  double lo = 0.0, hi = maxT;
  for (int i = 1; i <= 3000; ++i) {
    const double t = maxT * i / 3000;
    if ((b.value(Vec3(from + t * dir)) > 0.5f) != start) {
      hi = t;
      lo = maxT * (i - 1) / 3000;
      break;
    }
  }
  for (int k = 0; k < 40; ++k) {
    const double mid = 0.5 * (lo + hi);
    ((b.value(Vec3(from + mid * dir)) > 0.5f) == start ? lo : hi) = mid;
  }
  return from + 0.5 * (lo + hi) * dir;
}

}  // namespace

TEST_CASE("ShellPainter::the inside of the aperture takes the inside colour", "[organisms]") {
  ShellParams p = murexCabritii();
  p.bumps.enabled = false;
  p.varices.enabled = false;
  const ShellModel m = buildShell(p);
  const blobtree::CompiledBlob b = blobtree::compile(m.tree, m.shellRoot);
  ShellTextureOptions o;
  o.whorlColor = Vec3(0.6f, 0.4f, 0.2f);
  o.cordStrength = 0.0f;
  o.growthLineStrength = 0.0f;
  o.insideColor = Vec3(0.9f, 0.5f, 0.5f);
  const ShellPainter painter(p, m, o);
  ShellTextureOptions off = o;
  off.insideRadial = 0.0f;
  const ShellPainter plain(p, m, off);
  auto world = [&](const DVec3& q) { return Vec3(m.worldFromShell * glm::dvec4(q, 1.0)); };
  for (double back : {60.0, 150.0, 250.0}) {
    const double th = m.endDeg - back;
    const DVec3 c = p.spiral.point(th);
    const double d = p.spiral.curveSize(th);
    const DVec3 e = glm::normalize(DVec3(c.x, 0.0, c.z));
    INFO("theta " << th);
    REQUIRE(b.value(Vec3(c)) < 0.5f);  // hollow
    // Outwards from the centre: the inner wall (the opening's cut), then the outer surface.
    const DVec3 inner = crossing(b, c, e, 2.0 * d);
    const DVec3 outer = crossing(b, inner + 1e-4 * d * e, e, 2.0 * d);
    const double rIn = glm::length(inner - c) / d, rOut = glm::length(outer - c) / d;
    CHECK(rIn < 0.86);
    CHECK(rOut > 0.94);
    const Vec3 atInner = painter.partColor(ShellPart::Whorl, world(inner), Vec2(0.0f));
    const Vec3 atOuter = painter.partColor(ShellPart::Whorl, world(outer), Vec2(0.0f));
    CHECK(glm::length(atInner - o.insideColor) < 1e-5f);
    CHECK(glm::length(atOuter - o.whorlColor) < 1e-5f);
    // Off: the cut is painted as the whorl.
    CHECK(glm::length(plain.partColor(ShellPart::Whorl, world(inner), Vec2(0.0f)) - o.whorlColor) < 1e-5f);
  }
  // An older whorl, inside the shell's spire, is not the aperture: outside the opening's depth.
  const double old = m.endDeg - 700.0;
  const DVec3 c = p.spiral.point(old);
  const DVec3 e = glm::normalize(DVec3(c.x, 0.0, c.z));
  const DVec3 q = c + 0.8 * p.spiral.curveSize(old) * e;
  CHECK(glm::length(painter.partColor(ShellPart::Whorl, world(q), Vec2(0.0f)) - o.whorlColor) < 1e-5f);
}

TEST_CASE("ShellPainter::the canal's outside is not the aperture", "[organisms]") {
  // At λ 1.6, β 14° the canal runs where the next whorl would grow: the nearest generating
  // curve of a canal point is that whorl's, not yet grown, and it used to paint the canal
  // with the aperture's colour. Only curves grown so far (θ ≤ θ_end) count.
  ShellParams p = murexCabritii();
  p.spiral = HelicoSpiral{1.6, 14.0, 0.025};
  p.canal->length = 5.4f;
  p.bumps.enabled = false;
  p.varices.enabled = false;
  p.axialSpines.enabled = false;
  const ShellModel m = buildShell(p);
  const blobtree::CompiledBlob b = blobtree::compile(m.tree, m.shellRoot);
  const ShellPainter painter(p, m, ShellTextureOptions{});
  const HelicoSpiral& s = p.spiral;
  int surface = 0, pink = 0;
  for (double back : {0.0, 116.0, 232.0})
    for (double t = 0.35; t <= 0.95; t += 0.05) {
      // Around the canal's centre line below the aperture (its start runs through the
      // aperture's hollow), from outside inwards to its outer surface.
      const double th = m.endDeg - back;
      const DVec3 c(s.shellFromGenerating(th) * glm::dvec4(DVec3(p.canal->pointAt(s, t)), 1.0));
      const double d = s.curveSize(th);
      for (int k = 0; k < 8; ++k) {
        const double a = kPi * k / 4.0;
        const DVec3 dir(std::cos(a), 0.0, std::sin(a));
        const DVec3 from = c + 0.8 * d * dir;
        if (b.value(Vec3(from)) > 0.5f) continue;  // inside the body whorl or another part
        const DVec3 q = crossing(b, from, -dir, 0.8 * d);
        ++surface;
        pink += painter.insideWeight(painter.helicoCoords(Vec3(q))) > 0.0 ? 1 : 0;
      }
    }
  CHECK(surface > 150);
  CHECK(pink == 0);
}
