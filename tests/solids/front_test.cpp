#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/parallel.h"
#include "solids/distance_field.h"
#include "solids/front_field.h"
#include "solids/solid.h"
#include "tests/solids/grid_fixture.h"

using namespace sprig;
using namespace sprig::solids;

namespace {

SpeedFn constantSpeed(float v) {
  return [v](const std::vector<Vec3>&, std::vector<float>& out) { std::fill(out.begin(), out.end(), v); };
}

/// Lattice nodes of an n³ cube of step h from -n·h/2.
std::vector<Vec3> cube(int n, double h) {
  std::vector<Vec3> p;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) p.push_back(Vec3(DVec3(i, j, k) * h - 0.5 * n * h));
  return p;
}

/// A solid of one field: chocolate inside, white chocolate `thickness` outward.
Solid coated(FieldPtr field, double thickness) {
  Solid s;
  Layer in;
  in.fill = true;
  in.material = *s.materials.concrete("chocolate");
  Layer out;
  out.interior = false;
  out.thickness = thickness;
  out.material = *s.materials.concrete("white_chocolate");
  s.volumes.push_back(makeVolume(std::move(field), {in, out}));
  return s;
}

using test::gridAround;

/// Smallest and largest |p| of the visible interface's vertices where pick(p).
std::pair<double, double> outerRadii(const TetMesh& m, bool (*pick)(const DVec3&)) {
  double lo = 1e9, hi = 0;
  for (const auto& t : visibleInterface(m))
    for (uint32_t v : t.v)
      if (pick(m.positions[v])) {
        lo = std::min(lo, glm::length(m.positions[v]));
        hi = std::max(hi, glm::length(m.positions[v]));
      }
  return {lo, hi};
}

}  // namespace

TEST_CASE("marchFront: arrival times of closed form", "[solids][front]") {
  const double h = 0.05;
  const int n = 41;
  const std::array<int, 3> dims{n, n, n};
  const std::vector<Vec3> p = cube(n, h);
  SECTION("a plane front at unit and double speed: T = d / v exactly") {
    std::vector<float> d(p.size());
    for (size_t i = 0; i < p.size(); ++i) d[i] = p[i].x - 0.013f;
    for (float v : {1.0f, 2.0f}) {
      std::vector<float> speed(p.size(), v);
      const std::vector<float> t = marchFront(d, speed, dims, h, 10.0, false);
      double worst = 0;
      for (size_t i = 0; i < p.size(); ++i) worst = std::max(worst, std::abs(double(t[i]) - double(d[i]) / v));
      INFO("speed " << v);
      CHECK(worst < 1e-5);
    }
  }
  SECTION("a sphere: T = (|p| - R) / v within one cell, negative inside") {
    const double R = 0.5;
    std::vector<float> d(p.size());
    for (size_t i = 0; i < p.size(); ++i) d[i] = float(glm::length(DVec3(p[i])) - R);
    std::vector<float> speed(p.size(), 2.0f);
    const std::vector<float> t = marchFront(d, speed, dims, h, 10.0, false);
    double worst = 0;
    for (size_t i = 0; i < p.size(); ++i) {
      worst = std::max(worst, std::abs(double(t[i]) - double(d[i]) / 2));
      if (d[i] < -h) REQUIRE(t[i] < 0);
    }
    // First-order upwind differences: the error grows with the distance marched, below h/2 here.
    CHECK(worst < h / 2);
  }
  SECTION("values beyond the limit stay at ±limit") {
    std::vector<float> d(p.size());
    for (size_t i = 0; i < p.size(); ++i) d[i] = p[i].x;
    std::vector<float> speed(p.size(), 1.0f);
    const std::vector<float> t = marchFront(d, speed, dims, h, 0.3, false);
    for (size_t i = 0; i < p.size(); ++i) REQUIRE(std::abs(t[i]) <= 0.3f + 1e-6f);
    CHECK(*std::max_element(t.begin(), t.end()) == Approx(0.3));
  }
  SECTION("painted: a speed given only next to the zero set is carried along the normals") {
    // A plane front x = 0, painted speed 3 where z > 0 and 1 where z < 0: T = x / v(z) where
    // no faster path exists. Fronts from the fast side overtake the slow side's within the
    // wedge |z| < 2x/3 (T = x/3 + |z| there is less than x), so compare outside |z| > x.
    std::vector<float> d(p.size()), speed(p.size(), -1.0f);
    for (size_t i = 0; i < p.size(); ++i) {
      d[i] = p[i].x + 0.01f;
      if (std::abs(d[i]) < h) speed[i] = p[i].z > 0 ? 3.0f : 1.0f;
    }
    const std::vector<float> t = marchFront(d, speed, dims, h, 10.0, true);
    double worst = 0;
    for (size_t i = 0; i < p.size(); ++i)
      if (std::abs(p[i].z) > p[i].x + 4 * h && p[i].x > 0) worst = std::max(worst, double(std::abs(t[i] - d[i] / (p[i].z > 0 ? 3.0f : 1.0f))));
    CHECK(worst < 1e-4);
  }
}

TEST_CASE("interface velocity: velocity 2 gives layers twice as thick", "[solids][front]") {
  const double cell = 0.04, thickness = 0.2;
  const TetMesh one = meshSolid(coated(sphereField(DVec3(0.0), 1.0), thickness), gridAround(1.6, cell));
  // The front path (a procedure of the point), not the exact division by a constant.
  const TetMesh two = meshSolid(coated(frontField(sphereField(DVec3(0.0), 1.0), constantSpeed(2.0f), 2.0, false), thickness),
                                gridAround(1.6, cell));
  auto all = [](const DVec3&) { return true; };
  const auto [lo1, hi1] = outerRadii(one, all);
  const auto [lo2, hi2] = outerRadii(two, all);
  INFO("velocity 1: outer radius " << lo1 << ".." << hi1 << "; velocity 2: " << lo2 << ".." << hi2);
  CHECK(lo1 > 1 + thickness - cell);
  CHECK(hi1 < 1 + thickness + cell);
  CHECK(lo2 > 1 + 2 * thickness - cell);
  CHECK(hi2 < 1 + 2 * thickness + cell);
  const double ratio = ((lo2 + hi2) / 2 - 1) / ((lo1 + hi1) / 2 - 1);
  INFO("measured thickness ratio " << ratio);
  CHECK(ratio == Approx(2.0).epsilon(0.05));

  SECTION("a speed that varies over space: thick where it is fast") {
    SpeedFn halves = [](const std::vector<Vec3>& pts, std::vector<float>& out) {
      for (size_t i = 0; i < pts.size(); ++i) out[i] = pts[i].x > 0 ? 2.0f : 1.0f;
    };
    const TetMesh m = meshSolid(coated(frontField(sphereField(DVec3(0.0), 1.0), halves, 2.0, false), thickness), gridAround(1.6, cell));
    const auto [loF, hiF] = outerRadii(m, [](const DVec3& p) { return p.x > 0.9; });
    const auto [loS, hiS] = outerRadii(m, [](const DVec3& p) { return p.x < -0.9; });
    INFO("fast side " << loF << ".." << hiF << ", slow side " << loS << ".." << hiS);
    CHECK(hiF == Approx(1 + 2 * thickness).margin(cell));
    CHECK(hiS == Approx(1 + thickness).margin(cell));
  }
  SECTION("constant speed: an exact division") {
    const TetMesh c = meshSolid(coated(constantSpeedField(sphereField(DVec3(0.0), 1.0), 2.0), thickness), gridAround(1.6, cell));
    const auto [lo, hi] = outerRadii(c, all);
    CHECK(lo > 1 + 2 * thickness - cell);
    CHECK(hi < 1 + 2 * thickness + cell);
  }
}

TEST_CASE("volumeSurfaceField: the outermost interface of volumes in precedence", "[solids][front]") {
  Solid s;
  const int nut = *s.materials.concrete("nut"), choc = *s.materials.concrete("chocolate");
  Layer fillNut;
  fillNut.fill = true;
  fillNut.material = nut;
  Layer fillChoc = fillNut;
  fillChoc.material = choc;
  // Two overlapping balls: r 0.5 at x = -0.3 and r 0.4 at x = 0.4.
  std::vector<Volume> vs{makeVolume(sphereField(DVec3(-0.3, 0, 0), 0.5), {fillNut}),
                         makeVolume(sphereField(DVec3(0.4, 0, 0), 0.4), {fillChoc})};
  const std::vector<Vec3> probe{Vec3(-0.3f, 0, 0), Vec3(0.4f, 0, 0), Vec3(-0.8f, 0, 0), Vec3(0.8f, 0, 0), Vec3(0, 0.9f, 0),
                                Vec3(-0.9f, 0, 0), Vec3(1.0f, 0, 0)};
  SECTION("sign: inside either ball, outside both; zero on the union's surface") {
    const std::vector<float> f = volumeSurfaceField(vs)->sample(probe, 0.02, 2.0);
    CHECK(f[0] < 0);
    CHECK(f[1] < 0);
    CHECK(f[2] == Approx(0).margin(1e-6));
    CHECK(f[3] == Approx(0).margin(1e-6));
    CHECK(f[4] > 0);
  }
  SECTION("redistanced by a unit front: the Euclidean distance to the union") {
    const FieldPtr d = frontField(volumeSurfaceField(vs), constantSpeed(1.0f), 1.0, false);
    const std::vector<float> f = d->sample(probe, 0.02, 2.0);
    CHECK(f[5] == Approx(0.1).margin(0.02));
    CHECK(f[6] == Approx(0.2).margin(0.02));
    CHECK(f[0] == Approx(-0.5).margin(0.03));
  }
  SECTION("a nothing layer of an earlier volume is carved out of later ones") {
    Layer air;
    air.interior = false;
    air.thickness = 0.2;
    air.material = kNothing;
    std::vector<Volume> carved{makeVolume(sphereField(DVec3(-0.3, 0, 0), 0.5), {fillNut, air}), vs[1]};
    // (0.25, 0, 0) lies in the chocolate ball but within 0.2 outside the nut ball: air claims it.
    const std::vector<float> f = volumeSurfaceField(carved)->sample({Vec3(0.25f, 0, 0), Vec3(0.6f, 0, 0)}, 0.02, 2.0);
    CHECK(f[0] > 0);
    CHECK(f[1] < 0);
  }
}

TEST_CASE("frontField: the same bytes at 1 and 2 threads", "[solids][front]") {
  SpeedFn wavy = [](const std::vector<Vec3>& pts, std::vector<float>& out) {
    for (size_t i = 0; i < pts.size(); ++i) out[i] = 1.5f + std::sin(7 * pts[i].x + 3 * pts[i].y);
  };
  const FieldPtr f = frontField(boxField(DVec3(0.0), DVec3(1.0, 0.6, 0.8)), wavy, 2.5, false);
  const std::vector<Vec3> p = cube(30, 0.05);
  std::vector<float> one, two;
  {
    ThreadLimit limit(1);
    one = f->sample(p, 0.05, 1.0);
  }
  {
    ThreadLimit limit(2);
    two = f->sample(p, 0.05, 1.0);
  }
  REQUIRE(one.size() == two.size());
  CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(float)) == 0);
}
