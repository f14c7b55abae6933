#include <catch2/catch.hpp>

#include <cmath>

#include "organisms/shell_spiral.h"

using namespace sprig;
using namespace sprig::organisms;

TEST_CASE("HelicoSpiral::point", "[organisms]") {
  HelicoSpiral s;  // Murex cabritii: λ = 1.3, β = 22.5°, R₀ = 0.2 (Eq. 7)
  for (double theta = 0.0; theta <= 7 * 348.0; theta += 37.3) {
    const DVec3 p = s.point(theta);
    const double r = 0.2 * std::pow(1.3, theta / 360.0);                       // Eq. 1
    const double h = r / std::tan(radians(22.5));                              // Eq. 2
    CHECK(std::hypot(p.x, p.z) == Approx(r).margin(1e-6));
    CHECK(p.y == Approx(h).margin(1e-6));
    CHECK(std::atan2(-p.z, p.x) == Approx(std::remainder(radians(theta), 2 * kPi)).margin(1e-9));
  }
}

TEST_CASE("HelicoSpiral::curveSize", "[organisms]") {
  HelicoSpiral s;
  SECTION("the paper's own number: D = 0.341 R for the Murex") {
    CHECK(s.sizeRatio() == Approx(0.341).margin(5e-4));
  }
  SECTION("circles one whorl apart are tangent (Eq. 3)") {
    for (double theta : {0.0, 100.0, 500.0, 1400.0}) {
      const DVec3 a = s.point(theta), b = s.point(theta + 360.0);
      CHECK(glm::length(b - a) == Approx(s.curveSize(theta) + s.curveSize(theta + 360.0)).epsilon(1e-12));
    }
    HelicoSpiral turret{1.15, 10.0, 0.1};
    const DVec3 a = turret.point(40.0), b = turret.point(400.0);
    CHECK(glm::length(b - a) == Approx(turret.curveSize(40.0) + turret.curveSize(400.0)).epsilon(1e-12));
  }
}

TEST_CASE("HelicoSpiral::shellFromGenerating", "[organisms]") {
  HelicoSpiral s;
  const double theta = 250.0;
  const glm::dmat4 m = s.shellFromGenerating(theta);
  // Eq. 8: the origin goes to the spiral point; the unit x axis becomes D(θ) long.
  const DVec3 o = DVec3(m * glm::dvec4(0, 0, 0, 1));
  CHECK(glm::length(o - s.point(theta)) < 1e-12);
  const DVec3 x = DVec3(m * glm::dvec4(1, 0, 0, 0));
  CHECK(glm::length(x) == Approx(s.curveSize(theta)).epsilon(1e-12));
  // x points away from the axis, y stays along the axis.
  CHECK(glm::dot(glm::normalize(x), glm::normalize(DVec3(o.x, 0, o.z))) == Approx(1.0).epsilon(1e-12));
  const DVec3 y = DVec3(m * glm::dvec4(0, 1, 0, 0));
  CHECK(glm::normalize(y).y == Approx(1.0).epsilon(1e-12));
  CHECK(s.angleAtRadius(s.radius(theta)) == Approx(theta).epsilon(1e-12));
  // The tangent is the normalized derivative.
  const DVec3 fd = (s.point(theta + 1e-4) - s.point(theta - 1e-4));
  CHECK(glm::dot(glm::normalize(fd), s.tangent(theta)) == Approx(1.0).epsilon(1e-9));
}
