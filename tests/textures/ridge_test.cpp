#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "textures/ridge.h"

using namespace sprig;
using namespace sprig::textures;

TEST_CASE("RidgeShade", "[textures]") {
  const Vec3 p(0.31f, 1.7f, -0.2f);
  SECTION("the default changes nothing") {
    RidgeShade none;
    CHECK(none.none());
    for (double c : {0.0, 0.3, 1.0}) {
      CHECK(none.darkness(c, p) == 0.0);
      CHECK(none.slope(c, p) == 0.0);
    }
    CHECK(none.shadingNormal(Vec3(0, 0, 1), 0.5, Vec3(1, 0, 0), p) == Vec3(0, 0, 1));
  }
  SECTION("without folds: darkness D·c³, slope relief·6c(1 − c) (a smoothstep crest)") {
    RidgeOptions o;
    o.darkening = 0.6;
    o.relief = 1.3;
    RidgeShade r(o);
    for (int i = 0; i <= 20; ++i) {
      const double c = i / 20.0;
      CHECK(r.darkness(c, p) == Approx(0.6 * c * c * c).margin(1e-12));
      const double expected = (c > 0 && c < 1) ? 1.3 * 6 * c * (1 - c) : 0.0;
      CHECK(r.slope(c, p) == Approx(expected).margin(1e-5));
    }
  }
  SECTION("folds crowd toward the crest: L·(c_{k+1}^1.5 − c_k^1.5) = 1 between fold centres") {
    RidgeOptions o;
    o.darkening = 0.5;
    o.lines = 8;
    RidgeShade r(o);
    // The fold profile f from darkness = D·(c³ + 0.8·c·f·(1 − c³)); its peaks (f = 1) lie
    // where the phase L·c^1.5 + wander is an integer.
    const int n = 200000;
    std::vector<double> f(n + 1), peaks;
    for (int i = 1; i < n; ++i) {
      const double c = 0.02 + 0.9 * i / n, c3 = c * c * c;
      f[size_t(i)] = (r.darkness(c, p) / 0.5 - c3) / (0.8 * c * (1 - c3));
    }
    for (int i = 2; i + 1 < n; ++i)
      if (f[size_t(i)] > 0.99 && f[size_t(i)] >= f[size_t(i - 1)] && f[size_t(i)] > f[size_t(i + 1)])
        peaks.push_back(0.02 + 0.9 * i / n);
    // Phase from 8·0.02^1.5 to 8·0.92^1.5: 7 or 8 integers, each a peak.
    REQUIRE(peaks.size() >= 6);
    for (size_t k = 0; k + 1 < peaks.size(); ++k) {
      INFO("peaks at " << peaks[k] << ", " << peaks[k + 1]);
      CHECK(8 * (std::pow(peaks[k + 1], 1.5) - std::pow(peaks[k], 1.5)) == Approx(1.0).margin(2e-4));
      if (k + 2 < peaks.size()) CHECK(peaks[k + 2] - peaks[k + 1] < peaks[k + 1] - peaks[k]);
    }
    for (int i = 0; i <= 100; ++i) {
      const double d = r.darkness(i / 100.0, p);
      CHECK(d >= 0.0);
      CHECK(d <= 0.5);
    }
  }
  SECTION("the shading normal tilts away from the seam by atan(slope)") {
    RidgeOptions o;
    o.relief = 0.8;
    RidgeShade r(o);
    const Vec3 n = glm::normalize(Vec3(0.2f, 0.3f, 1.0f));
    // A gradient with a normal component, which must not count.
    const Vec3 g = 3.0f * glm::normalize(glm::cross(n, Vec3(0, 1, 0))) + 5.0f * n;
    const Vec3 gt = glm::normalize(g - glm::dot(g, n) * n);
    for (double c : {0.1, 0.5, 0.9}) {
      const double s = 0.8 * 6 * c * (1 - c);
      const Vec3 m = r.shadingNormal(n, c, g, p);
      CHECK(glm::length(m) == Approx(1.0).margin(1e-6));
      CHECK(glm::dot(m, n) == Approx(1 / std::sqrt(1 + s * s)).margin(1e-5));
      CHECK(glm::dot(m, gt) == Approx(-s / std::sqrt(1 + s * s)).margin(1e-5));
    }
    CHECK(r.shadingNormal(n, 0.5, 2.0f * n, p) == n);  // no tangential gradient: unchanged
  }
}

TEST_CASE("RidgeArcs", "[textures]") {
  // A parent along +y of radius 0.1 through the origin; a branch of radius 0.05 leaving it
  // at 45° toward +x. The chart's pierce point is at y = rA·cot 45° = 0.1 on the +x side.
  constexpr double kPi = 3.14159265358979323846;
  const double rA = 0.1, rB = 0.05;
  RidgeArc arc;
  arc.point = Vec3(0.0f);
  arc.parentAxis = Vec3(0, 1, 0);
  arc.branchAxis = glm::normalize(Vec3(1, 1, 0));
  arc.parentRadius = static_cast<float>(rA);
  arc.branchRadius = static_cast<float>(rB);
  RidgeArcOptions o;
  o.darkening = 0.7;
  o.relief = 1.0;
  const RidgeArcs arcs({arc}, o);
  REQUIRE(arcs.size() == 1);
  // A point on the parent's bark at angle θ from the branch's side (+x) and height y.
  auto bark = [&](double theta, double y) {
    return Vec3(static_cast<float>(rA * std::cos(theta)), static_cast<float>(y), static_cast<float>(-rA * std::sin(theta)));
  };
  const double zApex = 1 / std::sin(kPi / 4) + o.rise;  // in branch radii above the pierce point
  const double yApex = rA + rB * zApex;

  SECTION("above the branch: the crest's closed-form profile D·(1 − t²)², t = (y − y_apex)/(width·r_B)") {
    // (From t = −0.69 up: lower on the crest's flank the point comes within 1.2 r_B of the
    // branch's axis, where the arc fades so as not to paint the branch.)
    for (int i = -12; i <= 30; ++i) {
      const double y = yApex + i * 0.001;
      const double t = (y - yApex) / (o.width * rB);
      const double expected = std::abs(t) < 1 ? 0.7 * (1 - t * t) * (1 - t * t) : 0.0;
      CHECK(arcs.sample(bark(0.0, y)).darkness == Approx(expected).margin(1e-5));
    }
  }
  SECTION("darker above the branch than below it along the vertical line through it") {
    double above = 0, below = 0;
    for (int i = 0; i <= 400; ++i) {
      const double y = -0.3 + 0.8 * i / 400;  // from well below P to well above the apex
      const double d = arcs.sample(bark(0.0, y)).darkness;
      (y > rA ? above : below) = std::max(y > rA ? above : below, d);
    }
    CHECK(above == Approx(0.7).margin(0.01));  // (samples 0.002 apart on a crest 0.035 wide)
    CHECK(below == 0.0);
  }
  SECTION("the arc curves down both sides, symmetric, and not on the parent's far side") {
    // The darkest height at x = ±2 r_B around the parent (θ = ±2 r_B / r_A) against the
    // crest z_c(2) = z_apex − droop·(√(4 + 0.64) − 0.8).
    const double theta = 2 * rB / rA;
    auto darkestY = [&](double th) {
      double best = -1, at = 0;
      for (int i = 0; i <= 4000; ++i) {
        const double y = 0.4 * i / 4000;
        const double d = arcs.sample(bark(th, y)).darkness;
        if (d > best) best = d, at = y;
      }
      return at;
    };
    const double zc = zApex - o.droop * (std::sqrt(4 + 0.64) - 0.8);
    CHECK(darkestY(theta) == Approx(rA + rB * zc).margin(2e-4));
    CHECK(darkestY(-theta) == Approx(darkestY(theta)).margin(1e-4));
    CHECK(darkestY(theta) < yApex - 0.02);
    for (int i = 0; i <= 100; ++i) {
      const double y = -0.3 + 0.8 * i / 100;
      CHECK(arcs.sample(bark(0.3, y)).darkness == Approx(arcs.sample(bark(-0.3, y)).darkness).margin(1e-9));
      CHECK(arcs.sample(bark(kPi, y)).darkness == 0.0);
    }
  }
  SECTION("the crest is raised: the height rises toward it from both sides, and shading tilts away") {
    const Vec3 up(0, 1, 0);
    const float d = static_cast<float>(0.5 * o.width * rB);
    const RidgeArcs::Sample lower = arcs.sample(bark(0.0, yApex - d)), upper = arcs.sample(bark(0.0, yApex + d));
    CHECK(glm::dot(lower.heightGradient, up) > 0.5f);
    CHECK(glm::dot(upper.heightGradient, up) < -0.5f);
    // Closed form on the apex line: dH/dy = relief·(−4t(1 − t²)), t = ±1/2: ∓1.5.
    CHECK(glm::dot(lower.heightGradient, up) == Approx(1.5).margin(1e-3));
    RidgeShade shade(RidgeOptions{}, std::make_shared<const RidgeArcs>(arcs));
    CHECK(shade.tilts());
    const Vec3 n(1, 0, 0);
    CHECK(shade.shadingNormal(n, 0.0, Vec3(0.0f), bark(0.0, yApex - d)).y < -0.5f);  // faces down below the crest
    CHECK(shade.shadingNormal(n, 0.0, Vec3(0.0f), bark(0.0, yApex + d)).y > 0.5f);
    // The arc's darkness combines with the seam's: 1 − (1 − seam)(1 − arc).
    CHECK(shade.darkness(0.0, bark(0.0, yApex)) == Approx(0.7).margin(1e-9));
  }
  SECTION("the grid finds each arc among many; degenerate arcs are left out") {
    std::vector<RidgeArc> many;
    for (int k = 0; k < 50; ++k) {
      RidgeArc a = arc;
      a.point = Vec3(static_cast<float>(3 * k), 0.0f, 0.0f);  // far apart
      many.push_back(a);
    }
    RidgeArc along = arc;
    along.branchAxis = arc.parentAxis;  // a branch along its parent
    many.push_back(along);
    RidgeArc flat = arc;
    flat.branchRadius = 0;
    many.push_back(flat);
    const RidgeArcs grid(many, o);
    CHECK(grid.size() == 50);
    for (int k = 0; k < 50; k += 7)
      for (double y : {yApex - 0.01, yApex, yApex + 0.012})
        CHECK(grid.sample(bark(0.0, y) + Vec3(static_cast<float>(3 * k), 0.0f, 0.0f)).darkness ==
              Approx(arcs.sample(bark(0.0, y)).darkness).margin(1e-6));
  }
}
