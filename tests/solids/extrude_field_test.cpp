#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <random>

#include "solids/extrude_field.h"

using namespace sprig;
using namespace sprig::solids;

namespace {

/// A w x h mask of the disc of radius rPx pixels about the image centre (pixel centres inside).
Mask2d discMask(int w, int h, double rPx) {
  Mask2d m;
  m.width = w;
  m.height = h;
  m.inside.resize(size_t(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      m.inside[size_t(y) * w + x] = std::hypot(x + 0.5 - w / 2.0, y + 0.5 - h / 2.0) <= rPx ? 1 : 0;
  return m;
}

float at(const FieldPtr& f, Vec3 p) { return f->sample({p}, 0.01, 1.0)[0]; }

}  // namespace

TEST_CASE("signedDistance2d: the exact Euclidean transform of a mask", "[solids]") {
  SECTION("one inside pixel: outside values are distances to its centre less half a pixel") {
    Mask2d m;
    m.width = m.height = 9;
    m.inside.assign(81, 0);
    m.inside[4 * 9 + 4] = 1;
    const std::vector<float> d = signedDistance2d(m, 1.0, 1.0, 0);
    CHECK(d[4 * 9 + 4] == Approx(-0.5));
    CHECK(d[0] == Approx(std::hypot(4.0, 4.0) - 0.5));
    CHECK(d[4 * 9 + 8] == Approx(3.5));
    CHECK(d[1 * 9 + 2] == Approx(std::hypot(2.0, 3.0) - 0.5));
  }
  SECTION("random masks match brute force (seeded)") {
    const unsigned seed = 20261202;
    std::mt19937 rng(seed);
    INFO("seed " << seed);
    for (int trial = 0; trial < 20; ++trial) {
      Mask2d m;
      m.width = 5 + int(rng() % 12);
      m.height = 5 + int(rng() % 12);
      m.inside.resize(size_t(m.width) * m.height);
      for (auto& v : m.inside) v = rng() % 4 == 0;
      const double pu = 0.5 + (rng() % 100) / 100.0, pv = 0.5 + (rng() % 100) / 100.0;
      const int pad = 3;
      const std::vector<float> d = signedDistance2d(m, pu, pv, pad);
      const int w = m.width + 2 * pad, h = m.height + 2 * pad;
      auto inside = [&](int x, int y) {
        x -= pad, y -= pad;
        return x >= 0 && y >= 0 && x < m.width && y < m.height && m.inside[size_t(y) * m.width + x];
      };
      bool any = false;
      for (auto v : m.inside) any = any || v;
      if (!any) continue;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          double best = 1e30;
          for (int y2 = 0; y2 < h; ++y2)
            for (int x2 = 0; x2 < w; ++x2)
              if (inside(x2, y2) != inside(x, y)) best = std::min(best, std::hypot((x - x2) * pu, (y - y2) * pv));
          const double want = inside(x, y) ? -(best - 0.5 * std::min(pu, pv)) : best - 0.5 * std::min(pu, pv);
          INFO("trial " << trial << " pixel " << x << "," << y);
          REQUIRE(d[size_t(y) * w + x] == Approx(want).margin(1e-4));
        }
    }
  }
}

TEST_CASE("extrudeField: a disc extruded into a cylinder", "[solids]") {
  // 200 x 200 pixels over 2 x 2 world units (0.01 per pixel), a disc of radius 0.5, the slab 0.2 <= y <= 0.6.
  ExtrudeOptions o;
  o.size = {2.0, 2.0};
  o.center = {0.0, 0.0};
  o.heightLo = 0.2;
  o.heightHi = 0.6;
  const FieldPtr f = extrudeField(discMask(200, 200, 50), o);
  const double px = 0.01;
  SECTION("inside: -radius at the centre, the slab ends nearer") {
    CHECK(at(f, Vec3(0, 0.4, 0)) == Approx(-0.2).margin(px));  // half the slab is nearer than the rim
    CHECK(at(f, Vec3(0.4, 0.4, 0)) == Approx(-0.1).margin(px));
    CHECK(at(f, Vec3(0, 0.25, 0.3)) == Approx(-0.05).margin(1e-4));
  }
  SECTION("the 2-D distance of a tall slab is -radius at the centre") {
    ExtrudeOptions tall = o;
    tall.heightLo = -5;
    tall.heightHi = 5;
    const FieldPtr g = extrudeField(discMask(200, 200, 50), tall);
    // The pixelated disc's nearest outside pixels lie on the diagonals, 49.5 pixels from the
    // centre: d is -0.49, a pixel and a tenth from the drawn circle's radius.
    CHECK(at(g, Vec3(0, 0, 0)) == Approx(-0.5).margin(1.2 * px));
    CHECK(at(g, Vec3(0, 1, -0.3)) == Approx(-0.2).margin(px));
  }
  SECTION("outside: distance to the rim, to the caps and to the rim's corner") {
    CHECK(at(f, Vec3(0.8, 0.4, 0)) == Approx(0.3).margin(px));
    CHECK(at(f, Vec3(0, 0.4, -0.7)) == Approx(0.2).margin(px));
    CHECK(at(f, Vec3(0, 0.9, 0)) == Approx(0.3).margin(1e-4));
    CHECK(at(f, Vec3(0, 0.1, 0.2)) == Approx(0.1).margin(1e-4));
    CHECK(at(f, Vec3(0.8, 1.0, 0)) == Approx(0.5).margin(px));  // hypot(0.3, 0.4)
    CHECK(at(f, Vec3(0.5 / std::sqrt(2.0) + 0.1, 0.4, 0.5 / std::sqrt(2.0) + 0.1)) == Approx(0.1 * std::sqrt(2.0)).margin(px));
  }
  SECTION("beyond the image: the padded transform, then the distance to its rectangle") {
    CHECK(at(f, Vec3(1.3, 0.4, 0)) == Approx(0.8).margin(px));    // in the padding
    CHECK(at(f, Vec3(3.0, 0.4, 0)) == Approx(2.5).margin(px));    // beyond it, along the axis: exact
    CHECK(at(f, Vec3(0, 0.4, -2.5)) == Approx(2.0).margin(px));
    CHECK(at(f, Vec3(3, 0.4, 3)) > 3.5f);
  }
  SECTION("bounds are the image rectangle times the slab") {
    const auto b = f->bounds();
    REQUIRE(b);
    CHECK(b->lo.x == Approx(-1));
    CHECK(b->hi.z == Approx(1));
    CHECK(b->lo.y == Approx(0.2));
    CHECK(b->hi.y == Approx(0.6));
  }
  SECTION("the top row lies at -z; another axis turns the image with it") {
    Mask2d m;
    m.width = m.height = 10;
    m.inside.assign(100, 0);
    for (int x = 0; x < 10; ++x) m.inside[size_t(x)] = 1;  // the top row
    ExtrudeOptions tall = o;
    tall.heightLo = -5;
    tall.heightHi = 5;
    const FieldPtr g = extrudeField(m, tall);
    CHECK(at(g, Vec3(0, 0, -0.9)) < 0);
    CHECK(at(g, Vec3(0, 0, 0.9)) > 0);
    tall.axis = DVec3(1, 0, 0);  // +y turned to +x: the plane's u becomes -y, v stays z
    const FieldPtr x = extrudeField(m, tall);
    CHECK(at(x, Vec3(0, 0, -0.9)) < 0);
    CHECK(at(x, Vec3(0, 0, 0.9)) > 0);
    CHECK(at(x, Vec3(4, 0.5, -0.9)) < 0);
    CHECK(at(x, Vec3(6, 0.5, -0.9)) == Approx(1.0).margin(0.1));
  }
  SECTION("an empty mask is outside everywhere; bad options throw") {
    Mask2d m;
    m.width = m.height = 4;
    m.inside.assign(16, 0);
    CHECK(at(extrudeField(m, o), Vec3(0, 0.4, 0)) > 1);
    ExtrudeOptions bad = o;
    bad.heightHi = bad.heightLo;
    CHECK_THROWS_AS(extrudeField(m, bad), std::invalid_argument);
    CHECK_THROWS_AS(extrudeField(Mask2d{}, o), std::invalid_argument);
  }
}

TEST_CASE("extrudeScaleProblem: pixel sides the transform's arithmetic keeps finite", "[solids]") {
  ExtrudeOptions o;
  SECTION("a pixel of 1e-12 to 1e12 world units passes") {
    o.size = {2048e-12, 2048e12};
    CHECK(extrudeScaleProblem(2048, 2048, o).empty());
  }
  SECTION("tiny, huge and NaN pixel sides are refused, naming the sizes") {
    o.size = {1e-300, 1.0};
    CHECK(extrudeScaleProblem(2, 2, o) ==
          "'size' [1e-300, 1] over 2 x 2 pixels makes pixels of 5e-301 x 0.5 world units; each side must lie in [1e-12, 1e+12]");
    o.size = {1.0, 1e300};
    CHECK_FALSE(extrudeScaleProblem(2, 2, o).empty());
    o.size = {1.0, std::nan("")};
    CHECK_FALSE(extrudeScaleProblem(2, 2, o).empty());
  }
  SECTION("extrudeField and signedDistance2d throw instead of running the transform") {
    // 1e-300 over 2 pixels once made the lower envelope's crossing -inf and the walk back
    // write before its array (heap corruption).
    Mask2d m;
    m.width = m.height = 2;
    m.inside = {1, 0, 0, 1};
    o.size = {1e-300, 1e-300};
    CHECK_THROWS_AS(extrudeField(m, o), std::invalid_argument);
    CHECK_THROWS_AS(signedDistance2d(m, 5e-301, 5e-301, 1), std::invalid_argument);
  }
  SECTION("at the smallest and largest pixel the distances are still exact") {
    Mask2d m;
    m.width = m.height = 9;
    m.inside.assign(81, 0);
    m.inside[4 * 9 + 4] = 1;
    for (double px : {kMinExtrudePixel, kMaxExtrudePixel}) {
      const std::vector<float> d = signedDistance2d(m, px, px, 0);
      INFO("pixel " << px);
      CHECK(d[4 * 9 + 4] == Approx(-0.5 * px));
      CHECK(d[0] == Approx((std::hypot(4.0, 4.0) - 0.5) * px));
      CHECK(d[4 * 9 + 8] == Approx(3.5 * px));
    }
  }
}
