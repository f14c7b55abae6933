#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "organisms/wind.h"
#include "tests/organisms/internode.h"

using namespace sprig;
using namespace sprig::organisms;
using lsystem::Skeleton;
using test::windTree;

namespace {

WindOptions wind(double speed) {
  WindOptions w;
  w.speed = speed;
  w.directionDeg = 90;  // toward +X
  w.seed = 3;
  return w;
}

double displacement(const Skeleton& a, const Skeleton& b, size_t i) { return glm::length(a.internodes[i].end - b.internodes[i].end); }

}  // namespace

TEST_CASE("swayInWind: no wind is the still tree", "[organisms][wind]") {
  const Skeleton sk = windTree();
  const Skeleton still = swayInWind(sk, wind(0), 1.25);
  REQUIRE(still.internodes.size() == sk.internodes.size());
  for (size_t i = 0; i < sk.internodes.size(); ++i) {
    CHECK(still.internodes[i].start == sk.internodes[i].start);
    CHECK(still.internodes[i].end == sk.internodes[i].end);
  }
  CHECK(still.organs[0].points == sk.organs[0].points);
}

TEST_CASE("swayInWind: rigid, connected, deterministic", "[organisms][wind]") {
  const Skeleton sk = windTree();
  const Skeleton a = swayInWind(sk, wind(12), 0.7), b = swayInWind(sk, wind(12), 0.7);
  for (size_t i = 0; i < sk.internodes.size(); ++i) {
    CHECK(a.internodes[i].end == b.internodes[i].end);  // same bytes
    CHECK(a.internodes[i].length() == Approx(sk.internodes[i].length()).epsilon(1e-12));
    const int p = sk.internodes[i].parent;
    if (p >= 0) CHECK(glm::length(a.internodes[i].start - a.internodes[p].end) < 1e-12);  // no tearing
  }
  CHECK(a.internodes[0].start == sk.internodes[0].start);  // the root stays put
  // The leaf keeps its shape and hangs on its twig's tip.
  const auto& l0 = sk.organs[0].points;
  const auto& l1 = a.organs[0].points;
  CHECK(glm::length(l1[2] - l1[0]) == Approx(glm::length(l0[2] - l0[0])).epsilon(1e-12));
  CHECK(glm::length(l1[0] - a.internodes[5].end) < 1e-12);
  // Another seed sways the branches differently.
  WindOptions other = wind(12);
  other.seed = 4;
  CHECK(glm::length(swayInWind(sk, other, 0.7).internodes[5].end - a.internodes[5].end) > 1e-6);
}

TEST_CASE("swayInWind: displacement grows with speed and with height", "[organisms][wind]") {
  const Skeleton sk = windTree();
  // The trunk's joints: higher joints move further, and the lean is downwind (+X).
  const Skeleton a = swayInWind(sk, wind(10), 0.0);
  double prev = 0;
  for (size_t i = 0; i < 4; ++i) {
    const double d = displacement(a, sk, i);
    CHECK(d > prev);
    CHECK(a.internodes[i].end.x - sk.internodes[i].end.x > 0);
    prev = d;
  }
  // Faster wind, further for every internode's tip, trunk and branches (at one moment).
  for (double t : {0.0, 0.4, 1.3}) {
    const Skeleton s5 = swayInWind(sk, wind(5), t), s10 = swayInWind(sk, wind(10), t), s20 = swayInWind(sk, wind(20), t);
    for (size_t i : {size_t(3), size_t(9)}) {
      CHECK(displacement(s5, sk, i) < displacement(s10, sk, i));
      CHECK(displacement(s10, sk, i) < displacement(s20, sk, i));
    }
  }
  std::printf("wind: trunk top moves %.4f at 5 m/s, %.4f at 10, %.4f at 20 (tree height 4)\n",
              displacement(swayInWind(sk, wind(5), 0), sk, 3), displacement(swayInWind(sk, wind(10), 0), sk, 3),
              displacement(swayInWind(sk, wind(20), 0), sk, 3));
}

TEST_CASE("swayInWind: no popping between frames", "[organisms][wind]") {
  // At 12 frames per second every point moves by a small fraction of the tree's height per
  // frame (the motions are sums of sines of at most a few hertz).
  const Skeleton sk = windTree();
  double worst = 0;
  for (int f = 0; f < 48; ++f) {
    const Skeleton a = swayInWind(sk, wind(15), f / 12.0), b = swayInWind(sk, wind(15), (f + 1) / 12.0);
    for (size_t i = 0; i < sk.internodes.size(); ++i) worst = std::max(worst, displacement(a, b, i));
    for (size_t o = 0; o < sk.organs.size(); ++o)
      for (size_t k = 0; k < sk.organs[o].points.size(); ++k)
        worst = std::max(worst, glm::length(a.organs[o].points[k] - b.organs[o].points[k]));
  }
  std::printf("wind 15 m/s: largest move of a point between frames at 12 fps %.4f (tree height 4)\n", worst);
  CHECK(worst > 0.0);
  CHECK(worst < 0.04 * 4.0);
}

TEST_CASE("swayInWind: cpfg's textured cylinders follow their internode without flutter", "[organisms][wind]") {
  // A textured cylinder (a mesh organ) continuing the trunk's top internode, beside a leaf
  // hanging on the same internode; the trunk tip's rotation carries both, the leaf flutters.
  Skeleton sk = windTree();
  const DVec3 top = sk.internodes[3].end;
  lsystem::Organ tube;
  tube.kind = lsystem::Organ::Kind::Surface;
  tube.name = lsystem::kTexturedCylinderName;
  tube.texture = 0;
  tube.position = top;
  tube.heading = DVec3(0, 1, 0);
  tube.points = {top + DVec3(0.1, 0, 0), top + DVec3(0.1, 1, 0)};
  tube.normals = {DVec3(1, 0, 0), DVec3(1, 0, 0)};
  tube.internode = 3;
  lsystem::Organ leaf = tube;
  leaf.name = "a";
  sk.organs.push_back(tube);
  sk.organs.push_back(leaf);
  const Skeleton a = swayInWind(sk, wind(12), 0.7);
  const lsystem::Organ& t = a.organs[3];
  const lsystem::Organ& l = a.organs[4];
  // The tube's axis stays the trunk's continuation: its points are the internode's tip plus
  // the tip's own rotation of their offsets, so the tube's direction is the internode's.
  const DVec3 dir = glm::normalize(a.internodes[3].end - a.internodes[3].start);
  CHECK(glm::length(glm::normalize(t.points[1] - t.points[0]) - dir) < 1e-9);
  CHECK(glm::length(t.position - a.internodes[3].end) < 1e-12);
  // Its normals turn with it (perpendicular to the axis, unit length).
  CHECK(std::abs(glm::dot(t.normals[0], dir)) < 1e-9);
  CHECK(glm::length(t.normals[0]) == Approx(1.0));
  // The leaf on the same internode flutters away from that direction.
  CHECK(glm::length(glm::normalize(l.points[1] - l.points[0]) - dir) > 1e-4);
}

namespace {

/// Rodrigues' rotation of v by angle about the unit axis k.
DVec3 rotate(const DVec3& v, const DVec3& k, double angle) {
  return v * std::cos(angle) + glm::cross(k, v) * std::sin(angle) + k * glm::dot(k, v) * (1.0 - std::cos(angle));
}

}  // namespace

TEST_CASE("swayInWind: the trunk's lean carries the whole crown", "[organisms][wind]") {
  // A trunk of two internodes with branches and sub-branches, drawn from a grammar as
  // tree_lime's: each internode is followed by a leaf module that falls, two steps later,
  // as f(0) (a move that goes nowhere), before the next laterals and the leader.
  const char* text = R"(lsystem: lean
derivation length: 3
axiom: F(1)L(0)[&(45)B]/(180)[&(45)B]F(1)L(0)[&(60)B]
B : * --> F(0.5)L(0)[+(30)F(0.3)L(0)[-(30)F(0.2)]]F(0.5)
L(k) : k < 1 --> L(k+1)
L(k) : k >= 1 --> f(0)
endlsystem
)";
  const lsystem::Grammar g = lsystem::parseGrammar(text, "lean.lsys");
  const lsystem::ModuleString str = lsystem::derive(g);
  const Skeleton sk = lsystem::Turtle(g.symbols(), {}).run(str);
  REQUIRE(sk.internodes.size() == 14);  // 2 trunk + 3 branches of 4 internodes

  // Every internode's chain of parents reaches the root internode, the trunk's base.
  const auto trunkOf = [&](size_t i) {  // the highest trunk internode that carries i
    int32_t c = static_cast<int32_t>(i), top = -1;
    for (size_t guard = 0; c >= 0 && guard <= sk.internodes.size(); ++guard) {
      if (sk.internodes[c].order == 0 && top < 0) top = c;
      if (sk.internodes[c].parent < 0) return c == 0 ? top : -1;
      c = sk.internodes[c].parent;
    }
    return int32_t{-1};
  };
  for (size_t i = 0; i < sk.internodes.size(); ++i) {
    CAPTURE(i);
    CHECK(trunkOf(i) >= 0);
  }
  REQUIRE(sk.internodes[0].parent == -1);
  REQUIRE(sk.internodes[9].order == 0);
  REQUIRE(sk.internodes[9].parent == 0);

  // Only the lean: the trunk's internodes turn about their bases by lean·length/height,
  // and everything they carry turns with them, rigidly. The first carries all (a rotation
  // about the trunk's base, the origin); the second, based at b = (0,1,0), adds its own turn.
  WindOptions w = wind(8);
  w.swayPerSpeed = 0;
  w.flutterPerSpeed = 0;
  const double t = 0.7;
  const WindRig rig = windRig(sk, w);
  double height = 0;
  for (const auto& in : sk.internodes) height = std::max({height, in.start.y, in.end.y});
  const double lean = w.leanPerSpeed2 * w.speed * w.speed * rig.gust(t);
  const double theta0 = lean * 1.0 / height, theta1 = lean * 1.0 / height;
  const DVec3 k(0, 0, -1);  // turns +Y toward +X, the wind's direction
  const DVec3 b(0, 1, 0);
  const Skeleton a = swayInWind(sk, w, t);
  size_t onFirst = 0, onSecond = 0;
  for (size_t i = 0; i < sk.internodes.size(); ++i) {
    CAPTURE(i);
    const int32_t top = trunkOf(i);
    auto expected = [&](const DVec3& p) {
      return top == 0 ? rotate(p, k, theta0) : rotate(b, k, theta0) + rotate(p - b, k, theta0 + theta1);
    };
    (top == 0 ? onFirst : onSecond)++;
    CHECK(glm::length(a.internodes[i].start - expected(sk.internodes[i].start)) < 1e-12);
    CHECK(glm::length(a.internodes[i].end - expected(sk.internodes[i].end)) < 1e-12);
  }
  CHECK(onFirst == 9);    // the first trunk internode and its two branches
  CHECK(onSecond == 5);   // the leader and its branch
  CHECK(a.internodes[13].end.x - sk.internodes[13].end.x > 0.01);  // the top branch's tip leans downwind
}
