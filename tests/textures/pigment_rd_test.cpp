#include <catch2/catch.hpp>

#include <cmath>

#include "textures/pigment_rd.h"

using namespace sprig::textures;

TEST_CASE("pigmentSteadyState", "[textures]") {
  PigmentRdOptions o;
  o.saturation = 0.0;
  o.baseB = 0.0;
  double a, b;
  pigmentSteadyState(o, a, b);
  // Closed form for κ = 0, b_b = 0: a* = (r_b + bₐ)/rₐ, b* = a*²/r_b.
  CHECK(a == Approx((o.decayB + o.baseA) / o.decayA).epsilon(1e-12));
  CHECK(b == Approx(a * a / o.decayB).epsilon(1e-12));
}

TEST_CASE("simulatePigment", "[textures]") {
  SECTION("without source noise the homogeneous state stays homogeneous") {
    PigmentRdOptions o;
    o.sourceNoise = 0.0;
    o.rows = 20;
    PigmentPattern p = simulatePigment(o);
    CHECK(p.rawMax - p.rawMin < 1e-9f * p.rawMax + 1e-12f);
    double a, b;
    pigmentSteadyState(o, a, b);
    CHECK(p.rawMax == Approx(a).epsilon(1e-6));
  }
  SECTION("source noise grows into a pattern (Turing instability, Da << Db)") {
    PigmentRdOptions o;
    o.rows = 120;
    PigmentPattern p = simulatePigment(o);
    REQUIRE(p.width == o.cells);
    REQUIRE(p.height == o.rows);
    REQUIRE(p.values.size() == size_t(o.cells) * o.rows);
    CHECK(p.rawMax > 2.0f * p.rawMin);
    // Last row: count pigmented cells; a pattern has several separated peaks, not all on/off.
    int on = 0, transitions = 0;
    for (int i = 0; i < p.width; ++i) {
      bool hi = p.values[size_t(p.height - 1) * p.width + i] > 0.5f;
      bool hiNext = p.values[size_t(p.height - 1) * p.width + (i + 1) % p.width] > 0.5f;
      on += hi;
      transitions += hi != hiNext;
    }
    CHECK(on > 0);
    CHECK(on < p.width);
    CHECK(transitions >= 4);
    for (float v : p.values) {
      REQUIRE(v >= 0.0f);
      REQUIRE(v <= 1.0f);
    }
  }
  SECTION("same seed, same bytes; another seed, another pattern") {
    PigmentRdOptions o;
    o.rows = 40;
    PigmentPattern p1 = simulatePigment(o), p2 = simulatePigment(o);
    CHECK(p1.values == p2.values);
    o.seed = 2;
    CHECK(simulatePigment(o).values != p1.values);
  }
  SECTION("sample wraps in u and clamps in v") {
    PigmentRdOptions o;
    o.rows = 10;
    PigmentPattern p = simulatePigment(o);
    CHECK(p.sample(0.3, 0.5) == Approx(p.sample(1.3, 0.5)).margin(1e-6));
    CHECK(p.sample(0.3, 1.5) == Approx(p.sample(0.3, 1.0)).margin(1e-6));
  }
  SECTION("unstable time steps are refused") {
    PigmentRdOptions o;
    o.dt = 2.0;
    CHECK_THROWS_AS(simulatePigment(o), std::invalid_argument);
  }
}
