#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

#include "blobtree/compiled.h"
#include "organisms/shell.h"
#include "organisms/shell_measure.h"

using namespace sprig;
using namespace sprig::organisms;

TEST_CASE("CanalOptions::centre line is an arc that ends parallel to the axis", "[organisms]") {
  const HelicoSpiral s{1.3, 22.5, 0.2};
  CanalOptions c;
  c.turnDeg = 60.0f;
  // Tip beside the axis: R/D = (λ+1)·sin β/(λ−1) = 2.3·0.382683/0.3.
  const double axisX = -2.3 * std::sin(22.5 * kPi / 180.0) / 0.3;
  CHECK(c.tipX(s) == Approx(axisX + 0.1).epsilon(1e-9));
  const Vec3 a = c.pointAt(s, 0.0), b = c.pointAt(s, 1.0);
  CHECK(a.x == Approx(-0.45f));
  CHECK(a.y == Approx(0.7f));
  CHECK(b.x == Approx(axisX + 0.1).epsilon(1e-5));
  CHECK(b.y == Approx(0.7 + 8.0).epsilon(1e-5));
  // Polyline length and directions, computed from points alone.
  const int n = 20000;
  double len = 0.0;
  Vec3 prev = a;
  for (int i = 1; i <= n; ++i) {
    const Vec3 q = c.pointAt(s, double(i) / n);
    len += glm::length(q - prev);
    prev = q;
  }
  CHECK(len == Approx(c.centreLength(s)).epsilon(1e-4));
  // Starts heading 60° from the axis direction, inwards; the straight part is vertical.
  const Vec3 d0 = glm::normalize(c.pointAt(s, 1e-4) - a);
  CHECK(std::atan2(-d0.x, d0.y) * 180.0 / kPi == Approx(60.0).margin(0.05));
  const double arcEnd = (c.start.x - c.tipX(s)) / (1.0 - std::cos(kPi / 3.0)) * (kPi / 3.0) / c.centreLength(s);
  const Vec3 d1 = glm::normalize(c.pointAt(s, arcEnd) - c.pointAt(s, arcEnd - 1e-4));
  CHECK(std::abs(d1.x) < 1e-3f);
  CHECK(c.pointAt(s, arcEnd).y == Approx(0.7 + c.arcHeight(s)).epsilon(1e-5));
  // The arc's height: Δx·sin 60°/(1 − cos 60°) = Δx·√3.
  CHECK(c.arcHeight(s) == Approx((-0.45 - axisX - 0.1) * std::sqrt(3.0)).epsilon(1e-6));
}

TEST_CASE("measureShell::the Murex's canal, aperture and spines", "[organisms]") {
  const ShellParams p = murexCabritii();
  const ShellModel m = buildShell(p);
  const blobtree::CompiledBlob b = blobtree::compile(m.tree, m.shellRoot);
  const ShellMeasures ms = measureShell(p, m, b);
  std::printf(
      "Murex measures (shell units): apex %.3f, suture %.3f, aperture base %.3f, canal tip %.3f; rest %.3f, body whorl %.3f, "
      "canal %.3f, total %.3f; canal/rest %.2f, canal/body %.2f, canal/total %.2f; aperture %.3f x %.3f (%.2f of total); "
      "varix spines %d (longest %.3f = %.2f of total), axial spines %d (longest %.3f = %.2f of canal)\n",
      ms.apexY, ms.sutureY, ms.apertureBaseY, ms.canalTipY, ms.restLength, ms.bodyWhorlLength, ms.canalLength,
      ms.totalLength, ms.canalLength / ms.restLength, ms.canalLength / ms.bodyWhorlLength,
      ms.canalLength / ms.totalLength, ms.apertureHeight, ms.apertureWidth, ms.apertureHeight / ms.totalLength,
      ms.varixSpines, ms.longestVarixSpine, ms.longestVarixSpine / ms.totalLength, ms.axialSpines,
      ms.longestAxialSpine, ms.longestAxialSpine / ms.canalLength);
  // Closed forms: the lip at θ_end = 2436°.
  const HelicoSpiral& s = p.spiral;
  const double te = 7 * 348.0, he = s.height(te), de = s.curveSize(te);
  CHECK(ms.apertureBaseY == Approx(he + de));
  CHECK(ms.bodyWhorlLength == Approx(de * (1.0 + std::cos(22.5 * kPi / 180.0))));
  // The apex: the first generating surface's top, within its calibrated radius.
  CHECK(ms.apexY > s.height(0.0) - 1.2 * s.curveSize(0.0));
  CHECK(ms.apexY < s.height(0.0) - 0.5 * s.curveSize(0.0));
  // The canal's tip, a tube open at its end, ends within its radius of the newest canal
  // copy's end centre.
  const Vec3 tipLocal = p.canal->pointAt(s, 1.0);
  const double tipY = he + tipLocal.y * de;
  CHECK(std::abs(ms.canalTipY - tipY) < p.canal->radiusEnd * de);
  // M. cabritii: the canal about as long as the rest of the shell (Rehder 1981; paper Fig. 13).
  CHECK(ms.canalLength / ms.restLength > 0.8);
  CHECK(ms.canalLength / ms.restLength < 1.25);
  // Spines: Table 1 over 21 varices (rows by whorl ⌈k/3⌉: 0, 1, 1, 3, 5, 8, 18 spines, three
  // varices each) and Table 2 below the last three (6 + 6 + 5).
  CHECK(ms.varixSpines == 3 * (0 + 1 + 1 + 3 + 5 + 8 + 18));
  CHECK(ms.axialSpines == 17);
  // The longest varix spine: σ 1.92 of whorl 7 · spine_length 0.9 · D(θ) at the lip varix
  // (21 · 116° = θ_end).
  CHECK(ms.longestVarixSpine == Approx(1.92 * 0.9 * de).epsilon(1e-5));
  CHECK(ms.longestAxialSpine == Approx(1.0 * 1.8 * de).epsilon(1e-5));
  // A smallish aperture (Rehder): hollow, under a third of the shell's length.
  CHECK(ms.apertureHeight > 0.0);
  CHECK(ms.apertureWidth > 0.0);
  CHECK(ms.apertureHeight < ms.totalLength / 3.0);
}
