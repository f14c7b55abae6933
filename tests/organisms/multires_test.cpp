#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "core/mesh.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "organisms/analysis.h"
#include "organisms/base_mesh.h"
#include "organisms/detail.h"
#include "organisms/multires.h"
#include "organisms/subdivision.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {

/// Index of the vertex nearest p.
uint32_t vertexAt(const std::vector<Vec3>& ps, const Vec3& p) {
  uint32_t best = 0;
  for (uint32_t i = 1; i < ps.size(); ++i)
    if (glm::length(ps[i] - p) < glm::length(ps[best] - p)) best = i;
  return best;
}

/// Seeds at the given points, vertex footprint.
Placement at(std::vector<Vec3> points) {
  Placement p;
  p.kind = Placement::Kind::Points;
  p.points = std::move(points);
  return p;
}

SynthesisResult run(const Subdivision& sub, const ControlMesh& base, DetailSet shape, SynthesisOptions o = {}) {
  SynthesisInput in;
  in.shapeA = std::move(shape);
  o.keepLevels = true;
  return synthesize(sub, base.positions, in, o);
}

float signedHeight(const SynthesisResult& r, int level, uint32_t v, const Vec3& normal) {
  return glm::dot(r.levelDetail[size_t(level)][v], normal);
}

}  // namespace

TEST_CASE("Subdivision face counts", "[organisms]") {
  const ControlMesh cube = cubeSphere(1.0f, 1);  // 6 quads
  const Subdivision sub(cube, 4);
  for (int l = 0; l <= 4; ++l) {
    CHECK(sub.topology(l).faceCount() == size_t(6) << (2 * l));  // 4^l per quad
    for (uint32_t s : sub.topology(l).faceSizes) REQUIRE(s == 4);
  }
  // Euler characteristic 2 at every level: V - E + F, with E = 2F for quads.
  for (int l = 0; l <= 4; ++l) CHECK(int(sub.vertexCount(l)) - int(sub.topology(l).faceCount()) == 2);
  // A triangle and a pentagon become 3 and 5 quads.
  ControlMesh mixed;
  mixed.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0.5f, 1.5f, 0}, {0, 1, 0}};
  mixed.faceSizes = {5};
  mixed.faceVertices = {0, 1, 2, 3, 4};
  CHECK(Subdivision(mixed, 1).topology(1).faceCount() == 5);
  CHECK(Subdivision(mixed, 2).topology(2).faceCount() == 20);
  // Open meshes keep every face (boundary interpolation "edge only").
  CHECK(Subdivision(plane(2.0f, 3), 2).topology(2).faceCount() == 9u * 16u);
}

TEST_CASE("Subdivision reproduces the Catmull-Clark weights of Fig. 1", "[organisms]") {
  const int n = 6;
  const ControlMesh grid = plane(6.0f, n);  // unit spacing, regular interior
  const Subdivision sub(grid, 1);
  const uint32_t centre = vertexAt(grid.positions, Vec3(0, 0, 0));
  std::vector<float> delta(grid.positions.size(), 0.0f);
  delta[centre] = 1.0f;
  std::vector<float> fine(sub.vertexCount(1));
  sub.interpolate(1, delta, fine);
  std::vector<Vec3> finePos(sub.vertexCount(1));
  sub.interpolate(1, grid.positions, finePos);
  const auto weightAt = [&](Vec3 p) { return fine[vertexAt(finePos, p)]; };
  // Vertex rule: 9/16 for the vertex, 3/32 per edge neighbour, 1/64 per diagonal neighbour;
  // seen from the centre's coefficient in the children of the neighbours:
  CHECK(weightAt({0, 0, 0}) == Approx(9.0 / 16.0));
  CHECK(weightAt({1, 0, 0}) == Approx(3.0 / 32.0));
  CHECK(weightAt({1, 0, 1}) == Approx(1.0 / 64.0));
  // Edge rule: 3/8 for each end, 1/16 for the four others; face rule: 1/4 each.
  CHECK(weightAt({0.5f, 0, 0}) == Approx(3.0 / 8.0));
  CHECK(weightAt({0.5f, 0, 1}) == Approx(1.0 / 16.0));
  CHECK(weightAt({0.5f, 0, 0.5f}) == Approx(1.0 / 4.0));
  // Vertex v of level 0 is vertex v of level 1.
  CHECK(glm::length(finePos[centre]) < 1e-6f);
  // Weights add up to 1 (affine invariance).
  double sum = 0;
  for (float w : fine) sum += w;
  CHECK(sum == Approx(4.0));  // the centre's mass spreads with the refinement's 4x density
}

TEST_CASE("Base meshes are closed, outward and manifold", "[organisms]") {
  const auto check = [](const ControlMesh& m, bool closed) {
    const Subdivision sub(m, 2);
    const Mesh tri = limitMesh(sub, referenceLevels(sub, m.positions).back());
    const MeshTopology topo = analyzeTopology(tri);
    CHECK(topo.manifold());
    CHECK(topo.closed() == closed);
    if (closed) CHECK(signedVolume(tri) > 0);
  };
  check(cubeSphere(1.0f, 2), true);
  check(torus(1.0f, 0.3f, 8, 6), true);
  check(cylinder(0.5f, 2.0f, 8, 3, true), true);
  check(cylinder(0.5f, 2.0f, 8, 3, false), false);
  check(plane(1.0f, 4), false);
  check(revolution([](double t) { return std::sin(t); }, 0.0, kPi, 8, 6), true);
  // The cube-sphere's limit volume is below the sphere's (4/3 pi): Catmull-Clark's
  // averaging shrinks a coarse control mesh (by 22% for 3 x 3 quads per cube face).
  const ControlMesh cs = cubeSphere(1.0f, 3);
  const Subdivision sub(cs, 3);
  const double vol = signedVolume(limitMesh(sub, referenceLevels(sub, cs.positions).back()));
  CHECK(vol > 0.75 * 4.18879);
  CHECK(vol < 4.18879);
  // An open plane of 4x4 quads at level 2 has 4 * 4 * 4 boundary edges (16 per side).
  const Subdivision ps(plane(1.0f, 4), 2);
  CHECK(analyzeTopology(limitMesh(ps, referenceLevels(ps, plane(1.0f, 4).positions).back())).boundaryEdges == 64);
}

TEST_CASE("Berry dome height at its seed", "[organisms]") {
  const ControlMesh grid = plane(2.0f, 8);
  const Subdivision sub(grid, 2);
  BerryOptions o;
  o.radius = 0.4f;
  o.levels = {1, 1};
  o.placement = at({Vec3(0, 0, 0)});
  const SynthesisResult r = run(sub, grid, {makeBerry(o)});
  const auto& smooth = r.levelSmooth[1];
  const uint32_t seed = vertexAt(smooth, Vec3(0.0f));
  int inside = 0;
  for (uint32_t v = 0; v < smooth.size(); ++v) {
    const float d = glm::length(smooth[v] - smooth[seed]);
    const float expect = d < o.radius ? o.radius * std::sqrt(1 - d * d / (o.radius * o.radius)) : 0.0f;
    REQUIRE(signedHeight(r, 1, v, Vec3(0, 1, 0)) == Approx(expect).margin(1e-6));
    inside += d < o.radius;
  }
  CHECK(signedHeight(r, 1, seed, Vec3(0, 1, 0)) == Approx(o.radius));
  CHECK(inside > 8);
}

TEST_CASE("Berry seeds cluster on the domes of the level above", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  const Subdivision sub(ball, 4);
  BerryOptions o;
  o.radius = 0.3f;
  o.placement.spacing = 0.55f;
  o.levels = {1, 3};
  const SynthesisResult r = run(sub, ball, {makeBerry(o)});
  // Every level raises the surface (domes only push out) and the domes shrink by the ratio.
  for (int l = 1; l <= 3; ++l) {
    float maxH = 0;
    for (size_t v = 0; v < r.levelDetail[size_t(l)].size(); ++v)
      maxH = std::max(maxH, glm::length(r.levelDetail[size_t(l)][v]));
    CHECK(maxH <= o.radius * std::pow(o.ratio, float(l - 1)) * 1.0001f);
    CHECK(maxH >= 0.9f * o.radius * std::pow(o.ratio, float(l - 1)));
  }
  CHECK(analyzeTopology(limitMesh(sub, r.positions)).closed());
}

TEST_CASE("Rock amplitude halves per level", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  const Subdivision sub(ball, 6);
  RockOptions o;
  o.amplitude = 0.1f;
  o.frequency = 1.5f;
  o.levels = {1, 6};
  const SynthesisResult r = run(sub, ball, {makeRock(o)});
  std::vector<double> rms;
  for (int l = 1; l <= 6; ++l) {
    double sum = 0;
    for (const Vec3& d : r.levelDetail[size_t(l)]) sum += double(glm::dot(d, d));
    rms.push_back(std::sqrt(sum / double(r.levelDetail[size_t(l)].size())));
  }
  for (size_t i = 1; i < rms.size(); ++i) {
    INFO("level " << i + 1 << ": rms " << rms[i] << " / " << rms[i - 1]);
    CHECK(rms[i] / rms[i - 1] == Approx(0.5).margin(0.1));
  }
  // Level 0 gets nothing: the control mesh is unchanged.
  for (size_t v = 0; v < ball.positions.size(); ++v) REQUIRE(r.levelPositions[0][v] == ball.positions[v]);
}

TEST_CASE("Tentacle tip follows the pseudo-code", "[organisms]") {
  const ControlMesh grid = plane(2.0f, 8);
  const Subdivision sub(grid, 5);
  TentacleOptions o;
  o.length = 0.05f;
  o.angleDeg = 30;
  o.levels = {1, 4};
  o.placement = at({Vec3(0, 0, 0)});
  const SynthesisResult r = run(sub, grid, {makeTentacle(o)});
  const uint32_t tip = vertexAt(grid.positions, Vec3(0.0f));  // vertex v at every level
  for (int k = 1; k <= 4; ++k) {
    std::vector<Frame> frames(sub.vertexCount(k));
    computeFrames(sub.topology(k), r.levelSmooth[size_t(k)], frames);
    const double th = radians(30.0), ph = kPi / 3 * k, sign = k % 2 == 0 ? -1 : 1;  // tangential flip
    const Vec3 local = float(o.length * k) * Vec3(float(sign * std::sin(th + ph)), float(sign * std::cos(th + ph)), 1.0f);
    const Vec3 expect = r.levelSmooth[size_t(k)][tip] + frames[tip].toWorld(local);
    INFO("level " << k);
    CHECK(glm::length(r.levelPositions[size_t(k)][tip] - expect) < 1e-6f);
  }
  // Closed form at level 1 on the plane: the frame is the plane's (normal +y).
  std::vector<Frame> f1(sub.vertexCount(1));
  computeFrames(sub.topology(1), r.levelSmooth[1], f1);
  CHECK(glm::length(f1[tip].n - Vec3(0, 1, 0)) < 1e-6f);
  const Vec3 tip1 = r.levelPositions[1][tip];
  CHECK(tip1.y == Approx(0.05));
  CHECK(glm::length(Vec2(tip1.x, tip1.z)) == Approx(0.05));
  // Levels beyond the range add nothing at the tip.
  CHECK(glm::length(r.levelDetail[5][tip]) == 0.0f);
}

TEST_CASE("A rotated base gives the rotated result", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  ControlMesh turned = ball;
  const glm::mat3 R = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(Vec3(1, 2, 3))));
  for (Vec3& p : turned.positions) p = R * p;
  const Subdivision sub(ball, 4);  // same topology
  TentacleOptions t;
  t.placement.kind = Placement::Kind::ControlVertices;
  t.length = 0.03f;
  BerryOptions b;
  b.radius = 0.25f;
  b.placement.spacing = 0.5f;
  b.levels = {2, 3};
  MushroomOptions m;
  m.placement = at({ball.positions[3]});
  MushroomOptions mt = m;
  mt.placement = at({turned.positions[3]});
  const SynthesisResult a = run(sub, ball, {makeTentacle(t), makeBerry(b), makeMushroom(m)});
  const SynthesisResult c = run(sub, turned, {makeTentacle(t), makeBerry(b), makeMushroom(mt)});
  float worst = 0;
  for (size_t v = 0; v < a.positions.size(); ++v) worst = std::max(worst, glm::length(R * a.positions[v] - c.positions[v]));
  CHECK(worst < 2e-5f);
}

TEST_CASE("Blend: alpha 0 and 1 give each shape, widths follow c/2^(l-1)", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  const Subdivision sub(ball, 5);
  RockOptions ro;
  ro.amplitude = 0.08f;
  TentacleOptions to;
  to.placement.kind = Placement::Kind::ControlVertices;
  const DetailSet A = {makeRock(ro)}, B = {makeTentacle(to)};
  const auto blended = [&](float offset, bool sharp) {
    auto plane = std::make_shared<PlaneAlpha>();
    plane->normal = Vec3(1, 2, 0);
    plane->offset = offset;
    plane->width = 0.4f;
    plane->sharp = sharp;
    SynthesisInput in{A, B, plane, {}};
    SynthesisOptions o;
    o.keepLevels = true;
    return synthesize(sub, ball.positions, in, o);
  };
  const SynthesisResult onlyA = run(sub, ball, A), onlyB = run(sub, ball, B);
  const SynthesisResult zero = blended(100.0f, true), one = blended(-100.0f, true);
  CHECK(std::memcmp(zero.positions.data(), onlyA.positions.data(), zero.positions.size() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(one.positions.data(), onlyB.positions.data(), one.positions.size() * sizeof(Vec3)) == 0);

  for (bool sharp : {true, false}) {
    const SynthesisResult mid = blended(0.0f, sharp);
    const auto levels = referenceLevels(sub, ball.positions);
    const Vec3 n = glm::normalize(Vec3(1, 2, 0));
    for (int l = 1; l <= 5; ++l) {
      float lo = 1e9f, hi = -1e9f;
      for (size_t v = 0; v < levels[size_t(l)].size(); ++v) {
        const float a = mid.levelAlpha[size_t(l)][v];
        if (a <= 0 || a >= 1) continue;
        const float s = glm::dot(n, levels[size_t(l)][v]);
        lo = std::min(lo, s), hi = std::max(hi, s);
      }
      const float width = sharp ? 0.4f / float(1 << (l - 1)) : 0.4f;
      const float sample = meanEdgeLength(sub.topology(l), levels[size_t(l)]);
      INFO("level " << l << (sharp ? " sharp" : " soft") << ": measured " << hi - lo << ", expected " << width);
      CHECK(hi - lo <= width);
      CHECK(hi - lo >= width - 2 * sample);
    }
  }
}

TEST_CASE("Painted alpha: the paint refined with the surface, sharpened per level", "[organisms]") {
  // Paint m = 1/2 + x/4 on a plane: Catmull-Clark reproduces linear functions, so at every
  // level m_l = 1/2 + x/4 exactly and alpha_l = smoothstep(1/2 + (x/4) 2^(l-1) / width).
  const ControlMesh base = plane(2.0f, 8);
  const Subdivision sub(base, 4);
  const auto levels = referenceLevels(sub, base.positions);
  for (bool sharp : {true, false}) {
    auto painted = std::make_shared<PaintedAlpha>();
    for (const Vec3& p : base.positions) painted->control.push_back(0.5f + p.x / 4);
    painted->sharp = sharp;
    painted->width = 0.5f;
    for (int l = 0; l <= 4; ++l) {
      LevelView view;
      view.level = l;
      view.subdivision = &sub;
      view.reference = levels[size_t(l)];
      std::vector<float> alpha(levels[size_t(l)].size());
      painted->evaluate(view, alpha);
      const float gain = (sharp ? float(1 << std::max(0, l - 1)) : 1.0f) / 0.5f;
      float worst = 0;
      for (size_t v = 0; v < alpha.size(); ++v) {
        const float x = std::clamp(0.5f + levels[size_t(l)][v].x / 4 * gain, 0.0f, 1.0f);
        worst = std::max(worst, std::fabs(alpha[v] - x * x * (3 - 2 * x)));
      }
      INFO("level " << l << (sharp ? " sharp" : " soft"));
      CHECK(worst < 1e-5f);
    }
  }
  // Paint 1 everywhere is shape B exactly.
  RockOptions ro;
  const DetailSet A = {makeRock(ro)};
  ro.seed = 9;
  const DetailSet B = {makeRock(ro)};
  auto full = std::make_shared<PaintedAlpha>();
  full->control.assign(base.positions.size(), 1.0f);
  const SynthesisResult blended = synthesize(sub, base.positions, SynthesisInput{A, B, full, {}});
  const SynthesisResult onlyB = run(sub, base, B);
  CHECK(std::memcmp(blended.positions.data(), onlyB.positions.data(), onlyB.positions.size() * sizeof(Vec3)) == 0);
}

TEST_CASE("Local modification scales details near a point only", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  const Subdivision sub(ball, 4);
  RockOptions ro;
  ro.amplitude = 0.08f;
  SynthesisInput in;
  in.shapeA = {makeRock(ro)};
  Modification m;
  m.center = Vec3(0, 1, 0);
  m.radius = 0.5f;
  m.gains = {1, 1, 0, 3};  // level 2 removed, level 3 tripled near the pole
  in.modifications = {m};
  SynthesisOptions o;
  o.keepLevels = true;
  const SynthesisResult mod = synthesize(sub, ball.positions, in, o);
  const SynthesisResult plain = run(sub, ball, in.shapeA);
  const auto levels = referenceLevels(sub, ball.positions);
  const uint32_t pole2 = vertexAt(levels[2], Vec3(0, 1, 0));
  CHECK(glm::length(mod.levelDetail[2][pole2]) < 1e-7f);
  CHECK(glm::length(plain.levelDetail[2][pole2]) > 0);
  // Far from the point nothing changes.
  const uint32_t far4 = vertexAt(levels[4], Vec3(0, -1, 0));
  CHECK(glm::length(mod.levelDetail[4][far4] - plain.levelDetail[4][far4]) < 1e-6f);
}

TEST_CASE("Synthesis gives the same bytes at 1 and 2 threads", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  const Subdivision sub(ball, 5);
  RockOptions ro;
  BerryOptions bo;
  bo.placement.spacing = 0.5f;
  const DetailSet set = {makeRock(ro), makeBerry(bo)};
  std::vector<Vec3> one, two;
  {
    ThreadLimit limit(1);
    one = run(sub, ball, set).positions;
  }
  {
    ThreadLimit limit(2);
    two = run(sub, ball, set).positions;
  }
  REQUIRE(one.size() == two.size());
  CHECK(std::memcmp(one.data(), two.data(), one.size() * sizeof(Vec3)) == 0);
}

TEST_CASE("The mushroom profile is a simple curve at every growth", "[organisms]") {
  MushroomOptions o;
  const MushroomCurve curve(o);
  // Sample the profile scaled by growth W (the shape after part of its levels) and check
  // that no two non-adjacent segments cross.
  for (float W : {0.1f, 0.35f, 0.7f, 1.0f}) {
    std::vector<Vec2> c;
    const int n = 400;
    for (int i = 0; i <= n; ++i) {
      const float rho = o.footprint * float(i) / float(n);
      const Vec2 p = curve(rho);
      c.emplace_back(rho + W * (p.x - rho), W * p.y);
    }
    const auto cross = [](Vec2 a, Vec2 b) { return a.x * b.y - a.y * b.x; };
    int crossings = 0;
    for (int i = 0; i < n; ++i)
      for (int j = i + 2; j < n; ++j) {
        const Vec2 p = c[size_t(i)], r = c[size_t(i) + 1] - p, q = c[size_t(j)], s = c[size_t(j) + 1] - q;
        const float den = cross(r, s);
        if (std::abs(den) < 1e-12f) continue;
        const float t = cross(q - p, s) / den, u = cross(q - p, r) / den;
        crossings += t > 0 && t < 1 && u > 0 && u < 1;
      }
    INFO("growth " << W);
    CHECK(crossings == 0);
  }
}

// The mushroom planet's (Fig. 8b) stalks and feet streaked and its caps' rims were notched:
// the profile's stalk took a fixed 0.2 of the footprint's radius for a height 6 times that
// (slivers), and its corners were sharp, falling between the reference grid's vertices a
// different way at every angle round the seed. Each piece now takes a share of the
// footprint in proportion to its length, and the corners are rounded.
TEST_CASE("MushroomCurve: pieces share the footprint by their lengths, corners rounded", "[organisms]") {
  MushroomOptions planet;  // species/fig_org_08b_mushroom_planet.yaml
  planet.height = 0.24f;
  planet.capRadius = 0.145f;
  planet.capTop = 0.06f;
  planet.capUnder = 0.04f;
  planet.stalkRadius = 0.04f;
  planet.footprint = 0.16f;
  for (const MushroomOptions& o : {MushroomOptions{}, planet}) {
    const MushroomCurve curve(o);
    const std::array<float, 3> breaks = curve.breaks();
    CHECK(curve(0.0f).x == 0.0f);  // the apex on the axis
    CHECK(curve(o.footprint) == Vec2(o.footprint, 0.0f));  // the foot's edge on the ground
    // The curve's length, the share of u where it is the stalk's straight part, and the
    // sharpest turn between samples 1/2000 apart.
    const int n = 2000;
    float length = 0.0f, sharpest = 0.0f;
    int onStalk = 0;
    Vec2 last = curve(0.0f), step(0.0f);
    for (int i = 1; i <= n; ++i) {
      const Vec2 p = curve(o.footprint * float(i) / float(n));
      length += glm::length(p - last);
      onStalk += std::abs(p.x - o.stalkRadius) < 1e-5f && p.y > 0.0f && p.y < o.height - o.capUnder;
      if (glm::length(p - last) > 0 && glm::length(step) > 0)
        sharpest = std::max(sharpest, glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(p - last), glm::normalize(step)), -1.0f, 1.0f))));
      step = p - last;
      last = p;
    }
    const float want = (o.height - o.capUnder) / length;
    INFO("stalk " << o.height - o.capUnder << " of a profile " << length << " long (share " << want << "); breaks "
                  << breaks[0] << " " << breaks[1] << " " << breaks[2] << "; straight stalk " << float(onStalk) / n
                  << "; sharpest turn " << sharpest << "°");
    CHECK(breaks[2] - breaks[1] == Approx(want).margin(0.05));  // was 0.2 whatever its length; rounding shortens the curve by 10 %
    CHECK(float(onStalk) / n > breaks[2] - breaks[1] - 2.5f * kMushroomRounding);
    CHECK(breaks[0] == Approx(glm::length(Vec2(o.capRadius, o.capTop)) / length).margin(0.03));
    CHECK(sharpest < 10.0f);  // the rim turned by more than 90° at one sample
  }
}

TEST_CASE("Analysis then synthesis reproduces the resampled surface", "[organisms]") {
  const ControlMesh ball = cubeSphere(1.0f, 2);
  const Subdivision sub(ball, 5);
  SECTION("arbitrary samples on the finest level") {
    std::vector<Vec3> fine = referenceLevels(sub, ball.positions).back();
    Rng rng(7);
    for (Vec3& p : fine) p *= float(1.0 + 0.05 * rng.uniform(-1, 1));
    const AnalysisResult a = decompose(sub, fine, 2);
    SynthesisInput in;
    in.shapeA = {makeStoredDetail(a.details)};
    const SynthesisResult r = synthesize(sub, a.control, in);
    float worst = 0;
    for (size_t v = 0; v < fine.size(); ++v) worst = std::max(worst, glm::length(r.positions[v] - fine[v]));
    INFO("worst " << worst);
    CHECK(worst < 1e-5f * 2.0f);  // 1e-5 of the size (diameter 2)
  }
  SECTION("a captured sphere found by rays along the normals") {
    const float R = 1.05f;
    const SurfaceProbe sphere = [R](const Vec3& o, const Vec3& d, float maxDistance) -> std::optional<float> {
      // |o + t d| = R, the root nearest t = 0.
      const float b = glm::dot(o, d), c = glm::dot(o, o) - R * R, disc = b * b - c;
      if (disc < 0) return std::nullopt;
      const float t1 = -b + std::sqrt(disc), t2 = -b - std::sqrt(disc);
      const float t = std::abs(t1) < std::abs(t2) ? t1 : t2;
      return std::abs(t) <= maxDistance ? std::optional<float>(t) : std::nullopt;
    };
    AnalysisOptions o;
    o.maxDistance = 0.5f;
    const AnalysisResult a = analyze(sub, ball.positions, sphere, o);
    CHECK(a.misses == 0);
    for (const Vec3& p : a.resampled) REQUIRE(glm::length(p) == Approx(R).epsilon(1e-5));
    SynthesisInput in;
    in.shapeA = {makeStoredDetail(a.details)};
    const SynthesisResult r = synthesize(sub, a.control, in);
    float worst = 0;
    for (size_t v = 0; v < r.positions.size(); ++v) worst = std::max(worst, glm::length(r.positions[v] - a.resampled[v]));
    CHECK(worst < 2e-5f);
    const SurfaceProbe nothing = [](const Vec3&, const Vec3&, float) { return std::optional<float>(); };
    CHECK(analyze(sub, ball.positions, nothing, o).misses == sub.vertexCount(5));
  }
}
