#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "core/parallel.h"
#include "solids/distance_field.h"
#include "solids/operators.h"
#include "solids/particles.h"
#include "solids/solid.h"
#include "tests/solids/grid_fixture.h"
#include "tests/solids/tet_block.h"
#include "tests/solids/tet_checks.h"

using namespace sprig;
using namespace sprig::solids;

namespace {

/// A ball of radius 0.5: 0.12 of fired clay around a bronze core of radius 0.38.
struct Mold {
  Solid solid;
  TetMesh mesh;
  uint16_t clay = 0, bronze = 0;
};

Mold clayMold(double cell) {
  Mold m;
  const int clay = *m.solid.materials.concrete("fired_clay");
  const int bronze = *m.solid.materials.concrete("bronze");
  Layer outer;
  outer.thickness = 0.12;
  outer.material = clay;
  Layer core;
  core.fill = true;
  core.material = bronze;
  m.solid.volumes.push_back(makeVolume(sphereField(DVec3(0.0), 0.5), {outer, core}));
  m.mesh = meshSolid(m.solid, test::gridAround(0.6, cell));
  m.clay = uint16_t(clay);
  m.bronze = uint16_t(bronze);
  return m;
}

/// The tetrahedra of material id in order, as their vertices' positions (bytes to compare).
std::vector<DVec3> cornersOf(const TetMesh& m, uint16_t id) {
  std::vector<DVec3> out;
  for (size_t t = 0; t < m.tets.size(); ++t)
    if (m.materials[t] == id)
      for (uint32_t v : m.tets[t]) out.push_back(m.positions[v]);
  return out;
}

bool sameBytes(const std::vector<DVec3>& a, const std::vector<DVec3>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(DVec3)) == 0);
}

bool sameMesh(const TetMesh& a, const TetMesh& b) {
  return a.positions.size() == b.positions.size() && a.tets == b.tets && a.materials == b.materials &&
         std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(DVec3)) == 0 &&
         a.tints.size() == b.tints.size() &&
         (a.tints.empty() || std::memcmp(a.tints.data(), b.tints.data(), a.tints.size() * sizeof(Vec4)) == 0);
}

/// A slab 2 × 1 × 1 of stone whose top is level for x in [0, 1] and falls 0.5 over x in
/// [1, 2] (a slope of 26.6°): the block's vertices mapped by y -> y·s(x), s = 1 on the level
/// part and 1 − (x − 1)/2 on the slope (its kink on a grid line; the Jacobian det is s > 0).
TetMesh ramp(int perUnit) {
  TetMesh m = test::tetBlock({2 * perUnit, perUnit, perUnit}, DVec3(0.0), DVec3(2, 1, 1));
  for (DVec3& p : m.positions) p.y *= p.x <= 1 ? 1.0 : 1.0 - 0.5 * (p.x - 1);
  return m;
}

double topHeight(double x) { return x <= 1 ? 1.0 : 1.0 - 0.5 * (x - 1); }

/// The ramp (16 cells per unit) of stone, dirtied, then washed by 16,384 drops (four
/// batches: the later three see the earlier tracks) of radius 0.06 and strength 0.01, seed
/// 5, with the given attraction and meander (scale 0.15), at the given thread count.
TetMesh washedRamp(double attraction, double meander, int threads) {
  const std::vector<Material> mats = {*findBuiltinMaterial("stone")};
  ThreadLimit limit(threads);
  TetMesh m = ramp(16);
  dirt(m, mats, DirtOptions{});
  ParticleOptions o = particleDefaults(ParticleTool::Wash);
  o.particles = 16384;
  o.radius = 0.06;
  o.strength = 0.01;
  o.attraction = attraction;
  o.meander = meander;
  o.meanderScale = 0.15;
  o.seed = 5;
  runParticles(m, mats, o);
  return m;
}

}  // namespace

TEST_CASE("cutByField: a block cut at a sphere", "[solids][weathering]") {
  TetMesh m = test::tetBlock({6, 6, 6}, DVec3(-0.6), DVec3(1.2));
  const double before = [&] { double v = 0; for (size_t t = 0; t < m.tets.size(); ++t) v += m.volume(t); return v; }();
  auto sphere = [](const DVec3& p) { return glm::length(p - DVec3(0.1, 0.05, 0)) - 0.45; };
  const size_t n = cutByField(m, std::vector<uint8_t>(m.tets.size(), 1), sphere, nullptr, 0.0);
  CHECK(n > 0);
  test::checkValid(m);
  double after = 0;
  for (size_t t = 0; t < m.tets.size(); ++t) after += m.volume(t);
  CHECK(after == Approx(before).epsilon(1e-12));
  // No tetrahedron has vertices strictly on both sides; new vertices lie on the sphere.
  size_t straddling = 0;
  for (const auto& q : m.tets) {
    bool in = false, out = false;
    for (uint32_t v : q) in |= sphere(m.positions[v]) < -1e-9, out |= sphere(m.positions[v]) > 1e-9;
    straddling += in && out;
  }
  CHECK(straddling == 0);
  for (size_t v = 7 * 7 * 7; v < m.positions.size(); ++v) CHECK(std::abs(sphere(m.positions[v])) < 1e-9);
}

TEST_CASE("polish: no clay inside the sphere; bronze untouched; shine near the centre", "[solids][weathering]") {
  Mold mold = clayMold(0.05);
  const auto& mats = mold.solid.materials.materials;
  const TetMesh before = mold.mesh;
  PolishOptions o;
  o.affects = {mold.clay};

  SECTION("subtraction only: the clay volume taken is the sphere's share of the clay shell") {
    o.position = DVec3(0.55, 0, 0);
    o.size = 0.15;  // reaches radius 0.40 > 0.38: the bronze core is not reached
    const PolishStats st = polish(mold.mesh, mats, o);
    test::checkValid(mold.mesh);
    CHECK(st.splitEdges > 0);
    CHECK(st.removed > 0);
    for (size_t t = 0; t < mold.mesh.tets.size(); ++t)
      if (mold.mesh.materials[t] == mold.clay)
        for (uint32_t v : mold.mesh.tets[t]) REQUIRE(glm::length(mold.mesh.positions[v] - o.position) >= o.size - 1e-9 * o.size);
    CHECK(sameBytes(cornersOf(before, mold.bronze), cornersOf(mold.mesh, mold.bronze)));
    // Expected: the clay shell's volume inside the sphere, by a 200³ midpoint rule over the
    // sphere's box (within 6%: the cut faces are chords of the sphere, so the polyhedron taken lies inside it, and the shell is the grid's interpolation of two spheres; measured 3.6% under at cell 0.05).
    const int N = 200;
    double expected = 0;
    const double h = 2 * o.size / N;
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j)
        for (int k = 0; k < N; ++k) {
          const DVec3 p = o.position + DVec3(-o.size + (i + 0.5) * h, -o.size + (j + 0.5) * h, -o.size + (k + 0.5) * h);
          const double r = glm::length(p);
          if (glm::length(p - o.position) < o.size && r < 0.5 && r > 0.38) expected += h * h * h;
        }
    const double taken = test::volumeByMaterial(before)[mold.clay] - test::volumeByMaterial(mold.mesh)[mold.clay];
    INFO("taken " << taken << " expected " << expected);
    CHECK(taken == Approx(expected).epsilon(0.06));
  }

  SECTION("with shine: bronze within half the radius becomes shiny bronze, tints fall off with distance") {
    o.position = DVec3(0.4, 0, 0);
    o.size = 0.2;
    o.shiny = *mold.solid.materials.concrete("shiny_bronze");
    const PolishStats st = polish(mold.mesh, mold.solid.materials.materials, o);
    test::checkValid(mold.mesh);
    CHECK(st.shined > 0);
    CHECK(st.tinted > 0);
    for (size_t t = 0; t < mold.mesh.tets.size(); ++t) {
      const auto& q = mold.mesh.tets[t];
      const DVec3 c = (mold.mesh.positions[q[0]] + mold.mesh.positions[q[1]] + mold.mesh.positions[q[2]] + mold.mesh.positions[q[3]]) * 0.25;
      if (mold.mesh.materials[t] == uint16_t(o.shiny)) CHECK(glm::length(c - o.position) <= 0.5 * o.size + 1e-12);
      if (mold.mesh.materials[t] == mold.bronze) CHECK(glm::length(c - o.position) > 0.5 * o.size - 1e-12);
      if (mold.mesh.materials[t] == mold.clay)
        for (uint32_t v : q) REQUIRE(glm::length(mold.mesh.positions[v] - o.position) >= o.size * (1 - 1e-9));
    }
    REQUIRE(mold.mesh.tints.size() == mold.mesh.positions.size());
    for (size_t v = 0; v < mold.mesh.tints.size(); ++v)
      if (glm::length(mold.mesh.positions[v] - o.position) > 1.5 * o.size) CHECK(mold.mesh.tints[v].w == 0);
  }

  SECTION("bad options") {
    o.size = NAN;
    CHECK_THROWS_AS(polish(mold.mesh, mats, o), std::invalid_argument);
    o.size = 0.1;
    o.affects = {uint16_t(mats.size())};
    CHECK_THROWS_AS(polish(mold.mesh, mats, o), std::invalid_argument);
    CHECK(sameMesh(mold.mesh, before));
  }
}

TEST_CASE("polish replayed at a finer grid takes the same clay (section 3.3's replay)", "[solids][weathering]") {
  // The operation list is in world units, so the same file at a finer `grid` replays the
  // same cut on the finer mesh: the clay taken converges to the sphere's share of the clay
  // shell (a 200³ midpoint rule), and the bronze is untouched at both grids.
  PolishOptions o;
  o.position = DVec3(0.55, 0, 0);
  o.size = 0.15;
  const int N = 200;
  double expected = 0;
  const double h = 2 * o.size / N;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j)
      for (int k = 0; k < N; ++k) {
        const DVec3 p = o.position + DVec3(-o.size + (i + 0.5) * h, -o.size + (j + 0.5) * h, -o.size + (k + 0.5) * h);
        const double r = glm::length(p);
        if (glm::length(p - o.position) < o.size && r < 0.5 && r > 0.38) expected += h * h * h;
      }
  double error[2];
  size_t tets[2];
  const double cells[2] = {0.08, 0.04};
  for (int g = 0; g < 2; ++g) {
    Mold mold = clayMold(cells[g]);
    const TetMesh before = mold.mesh;
    o.affects = {mold.clay};
    polish(mold.mesh, mold.solid.materials.materials, o);
    test::checkValid(mold.mesh);
    CHECK(sameBytes(cornersOf(before, mold.bronze), cornersOf(mold.mesh, mold.bronze)));
    const double taken = test::volumeByMaterial(before)[mold.clay] - test::volumeByMaterial(mold.mesh)[mold.clay];
    error[g] = std::fabs(taken / expected - 1);
    tets[g] = mold.mesh.tets.size();
    INFO("cell " << cells[g] << ": taken " << taken << ", expected " << expected);
    CHECK(error[g] < 0.12);
  }
  INFO("relative errors " << error[0] << " (cell 0.08), " << error[1] << " (cell 0.04); tetrahedra " << tets[0] << ", " << tets[1]);
  CHECK(tets[1] > 4 * tets[0]);
  CHECK(error[1] < error[0]);
}

TEST_CASE("blendTint composes: blending toward c by w twice equals once by 1 - (1 - w)^2", "[solids][weathering]") {
  TetMesh m;
  m.positions = {DVec3(0.0)};
  blendTint(m, 0, Vec3(0.5f), 0.3);
  blendTint(m, 0, Vec3(0.5f), 0.3);
  CHECK(m.tints[0].w == Approx(1 - 0.7 * 0.7));
  CHECK(m.tints[0].x == Approx(0.5));
  // Face colour: start from material M = 1, dirt 0.5 at w 1, then white lichen 1 at 0.25 -> 0.625.
  TetMesh n;
  n.positions = {DVec3(0.0)};
  blendTint(n, 0, Vec3(0.5f), 1.0);
  blendTint(n, 0, Vec3(1.0f), 0.25);
  const float face = glm::mix(1.0f, n.tints[0].x, n.tints[0].w);
  CHECK(face == Approx(0.625));
  clearTint(n, 0, 0.5);
  CHECK(n.tints[0].w == Approx(0.5));
}

TEST_CASE("wash: more dirt goes where more particles pass (a slope against a level top)", "[solids][weathering]") {
  TetMesh m = ramp(8);
  std::vector<Material> mats = {*findBuiltinMaterial("stone")};
  DirtOptions d;
  d.color = Vec3(0.5f);
  const size_t dirty = dirt(m, mats, d);
  CHECK(dirty > 0);
  ParticleOptions o = particleDefaults(ParticleTool::Wash);
  o.particles = 4000;
  o.radius = 0.1;
  o.strength = 0.05;
  o.seed = 3;
  const TetMesh before = m;
  const ParticleStats st = runParticles(m, mats, o);
  test::checkValid(m);
  CHECK(st.landed > 3000);  // the footprint box is the ramp's: every particle lands
  CHECK(st.steps > 0);
  CHECK(m.positions == before.positions);
  CHECK(m.tets == before.tets);
  // Mean dirt left and passes on the top's vertices away from the edges.
  double dirtFlat = 0, dirtSlope = 0, passFlat = 0, passSlope = 0;
  int nFlat = 0, nSlope = 0;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const DVec3 p = m.positions[v];
    if (std::abs(p.y - topHeight(p.x)) > 1e-9 || p.z < 0.2 || p.z > 0.8) continue;
    if (p.x > 0.2 && p.x < 0.8) dirtFlat += m.tints[v].w, passFlat += st.passes[v], ++nFlat;
    if (p.x > 1.2 && p.x < 1.8) dirtSlope += m.tints[v].w, passSlope += st.passes[v], ++nSlope;
  }
  REQUIRE(nFlat > 10);
  REQUIRE(nSlope > 10);
  dirtFlat /= nFlat, dirtSlope /= nSlope, passFlat /= nFlat, passSlope /= nSlope;
  INFO("flat: dirt " << dirtFlat << ", passes " << passFlat << "; slope: dirt " << dirtSlope << ", passes " << passSlope);
  CHECK(passSlope > 2 * passFlat);
  CHECK(dirtSlope < dirtFlat);
  CHECK(dirtFlat < 1.0);  // the level top was washed too, by the drops that land there
  // The sides the rain never reaches keep their dirt (x = 0 face: no particle walks up it).
  for (size_t v = 0; v < m.positions.size(); ++v)
    if (m.positions[v].x == 0 && m.positions[v].y < 0.8) CHECK(m.tints[v].w == 1.0f);
}

TEST_CASE("wash attraction: later drops follow washed tracks, so the slope washes in streaks", "[solids][weathering]") {
  // The ramp's slope, washed with and without attraction. Streaks are variation across the
  // fall line: the dirt left on the slope's top vertices, averaged per column of equal z, varies
  // more between columns when drops steer toward what earlier batches cleaned.
  auto run = [](double attraction, int threads) { return washedRamp(attraction, 0, threads); };
  auto columnSpread = [](const TetMesh& m) {
    std::map<long, std::pair<double, int>> col;
    for (size_t v = 0; v < m.positions.size(); ++v) {
      const DVec3 p = m.positions[v];
      if (std::abs(p.y - topHeight(p.x)) > 1e-9 || p.x < 1.3 || p.x > 1.9 || p.z < 0.1 || p.z > 0.9) continue;
      auto& c = col[std::lround(p.z * 16)];
      c.first += m.tints[v].w;
      ++c.second;
    }
    double sum = 0, sum2 = 0;
    for (const auto& [z, c] : col) {
      const double mean = c.first / c.second;
      sum += mean;
      sum2 += mean * mean;
    }
    const double n = double(col.size());
    return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
  };
  const TetMesh plain = run(0, 2), streaky = run(4, 2), streaky1 = run(4, 1);
  const double a = columnSpread(plain), b = columnSpread(streaky);
  INFO("standard deviation of column means: plain " << a << ", attraction 4: " << b);
  CHECK(b > 10 * a);  // measured: 0.0010 against 0.053
  CHECK(sameMesh(streaky, streaky1));  // still the same bytes at 1 and 2 threads
  CHECK(!sameMesh(plain, streaky));
}

TEST_CASE("wash meander: streaks wander off the fall line", "[solids][weathering]") {
  // The ramp's slope washed in streaks (attraction 4), with and without meander. Straight
  // streaks run down the fall line (x), so the dirt left across the slope (per column of
  // equal z) in the slope's upper part matches the lower part's; meandering ones drift
  // sideways between the two, and the two profiles correlate less.
  auto run = [](double meander, int threads) { return washedRamp(4, meander, threads); };
  // Correlation of the column means of the dirt left for x in [1.25, 1.45] and in [1.65, 1.85].
  auto upperLower = [](const TetMesh& m) {
    std::map<long, std::array<double, 4>> col;  // z -> upper sum, count, lower sum, count
    for (size_t v = 0; v < m.positions.size(); ++v) {
      const DVec3 p = m.positions[v];
      if (std::abs(p.y - topHeight(p.x)) > 1e-9 || p.z < 0.1 || p.z > 0.9) continue;
      auto& c = col[std::lround(p.z * 16)];
      if (p.x > 1.25 && p.x < 1.45) c[0] += m.tints[v].w, c[1] += 1;
      if (p.x > 1.65 && p.x < 1.85) c[2] += m.tints[v].w, c[3] += 1;
    }
    std::vector<double> a, b;
    for (const auto& [z, c] : col) a.push_back(c[0] / c[1]), b.push_back(c[2] / c[3]);
    const double n = double(a.size());
    double ma = 0, mb = 0;
    for (size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
    double sab = 0, saa = 0, sbb = 0;
    for (size_t i = 0; i < a.size(); ++i) sab += (a[i] - ma) * (b[i] - mb), saa += (a[i] - ma) * (a[i] - ma), sbb += (b[i] - mb) * (b[i] - mb);
    return sab / std::sqrt(saa * sbb);
  };
  const TetMesh straight = run(0, 2), wandering = run(1, 2), wandering1 = run(1, 1);
  const double a = upperLower(straight), b = upperLower(wandering);
  INFO("correlation of the upper and lower profiles across the slope: straight " << a << ", meander 1: " << b);
  CHECK(a > 0.8);
  CHECK(b < a - 0.3);  // measured: 0.872 against 0.326
  CHECK(sameMesh(wandering, wandering1));  // the same bytes at 1 and 2 threads
  CHECK(!sameMesh(straight, wandering));
}

TEST_CASE("particle tools: the same bytes at 1 and 2 threads; unaffected materials unchanged", "[solids][weathering]") {
  Mold mold = clayMold(0.06);
  const auto& mats = mold.solid.materials.materials;
  auto run = [&](int threads) {
    ThreadLimit limit(threads);
    TetMesh m = mold.mesh;
    DirtOptions d;
    dirt(m, mats, d);
    ParticleOptions w = particleDefaults(ParticleTool::Wash);
    w.particles = 3000;
    w.seed = 11;
    runParticles(m, mats, w);
    ParticleOptions e = particleDefaults(ParticleTool::Erode);
    e.particles = 300;
    e.radius = 0.05;
    e.affects = {mold.clay};
    runParticles(m, mats, e);
    ParticleOptions l = particleDefaults(ParticleTool::Lichen);
    l.particles = 3000;
    runParticles(m, mats, l);
    return m;
  };
  const TetMesh a = run(1), b = run(2);
  CHECK(sameMesh(a, b));
  test::checkValid(a);
  CHECK(a.tets.size() != mold.mesh.tets.size());  // erode removed clay
  // Erosion only takes clay: the bronze tetrahedra's corners are the same bytes.
  CHECK(sameBytes(cornersOf(mold.mesh, mold.bronze), cornersOf(a, mold.bronze)));
}

TEST_CASE("lichen grows on top-facing faces only; erode removes spheres of the affected material", "[solids][weathering]") {
  TetMesh m = test::tetBlock({6, 6, 6}, DVec3(0.0), DVec3(1.0));
  std::vector<Material> mats = {*findBuiltinMaterial("stone")};
  ParticleOptions l = particleDefaults(ParticleTool::Lichen);
  l.particles = 2000;
  runParticles(m, mats, l);
  REQUIRE(m.tints.size() == m.positions.size());
  size_t topGreen = 0;
  for (size_t v = 0; v < m.positions.size(); ++v) {
    if (m.positions[v].y < 1 - 1e-12 && m.tints[v].w > 0) FAIL("lichen below the top at vertex " << v);
    topGreen += m.positions[v].y == 1 && m.tints[v].w > 0;
  }
  CHECK(topGreen == 49);  // every vertex of the 7 × 7 top

  TetMesh e = test::tetBlock({8, 8, 8}, DVec3(0.0), DVec3(1.0));
  ParticleOptions o = particleDefaults(ParticleTool::Erode);
  o.particles = 20;
  o.radius = 0.1;
  const double v0 = test::volumeByMaterial(e)[0];
  const ParticleStats st = runParticles(e, mats, o);
  test::checkValid(e);
  CHECK(st.removed > 0);
  const double v1 = test::volumeByMaterial(e)[0];
  // At most 20 half-balls are taken from the top (they overlap).
  CHECK(v0 - v1 > 0);
  CHECK(v0 - v1 <= 20 * (2.0 / 3.0) * 3.14159265358979 * 0.001 + 1e-12);
  for (size_t t = 0; t < e.tets.size(); ++t) CHECK(e.materials[t] == 0);
}

TEST_CASE("particle tools: bad options throw and change nothing", "[solids][weathering]") {
  TetMesh m = test::tetBlock({3, 3, 3}, DVec3(0.0), DVec3(1.0));
  std::vector<Material> mats = {*findBuiltinMaterial("stone")};
  const TetMesh before = m;
  ParticleOptions o = particleDefaults(ParticleTool::Wash);
  o.life = NAN;
  CHECK_THROWS_AS(runParticles(m, mats, o), std::invalid_argument);
  o = particleDefaults(ParticleTool::Wash);
  o.affects = {1};
  CHECK_THROWS_AS(runParticles(m, mats, o), std::invalid_argument);
  o = particleDefaults(ParticleTool::Wash);
  o.attraction = -1;
  CHECK_THROWS_WITH(runParticles(m, mats, o), Catch::Contains("'attraction' must be finite and not negative"));
  o.attraction = 0;
  o.meander = NAN;
  CHECK_THROWS_WITH(runParticles(m, mats, o), Catch::Contains("'meander' must be finite and not negative"));
  o.meander = 1;
  o.meanderScale = 0;
  CHECK_THROWS_WITH(runParticles(m, mats, o), Catch::Contains("'meander_scale' must be positive and finite"));
  DirtOptions d;
  d.color = Vec3(NAN);
  CHECK_THROWS_AS(dirt(m, mats, d), std::invalid_argument);
  CHECK(sameMesh(m, before));
}
