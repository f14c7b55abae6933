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
