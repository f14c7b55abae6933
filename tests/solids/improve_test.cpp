#include <catch2/catch.hpp>

#include <algorithm>
#include <map>

#include "core/mesh.h"
#include "core/parallel.h"
#include "solids/improve.h"
#include "solids/solid.h"
#include "solids/tet_io.h"
#include "tests/solids/grid_fixture.h"
#include "tests/solids/tet_checks.h"

using namespace sprig;
using namespace sprig::solids;
using test::checkValid;
using test::faceUses;
using test::meshOf;
using test::volumeByMaterial;

namespace {

/// Area of each interface (material pair; 0xFFFF is outside), from the interface triangles.
std::map<std::pair<int, int>, double> interfaceAreas(const TetMesh& m) {
  std::map<std::pair<int, int>, double> out;
  auto area = [&](const InterfaceTriangle& t) {
    return 0.5 * glm::length(glm::cross(m.positions[t.v[1]] - m.positions[t.v[0]], m.positions[t.v[2]] - m.positions[t.v[0]]));
  };
  for (const auto& t : visibleInterface(m)) out[{t.material, 0xFFFF}] += area(t);
  const auto between = materialInterfaces(m);
  for (size_t i = 0; i + 1 < between.size(); i += 2)
    out[{std::min(between[i].material, between[i + 1].material), std::max(between[i].material, between[i + 1].material)}] +=
        area(between[i]);
  return out;
}

/// A sphere of frosting 0.15 over a chocolate filling, white chocolate 0.1 outside.
Solid layeredSphere() {
  Solid s;
  auto layer = [&](bool interior, double thickness, const char* material) {
    Layer l;
    l.interior = interior;
    l.fill = thickness == 0;
    l.thickness = thickness == 0 ? 1.0 : thickness;
    l.material = *s.materials.concrete(material);
    return l;
  };
  s.volumes.push_back(makeVolume(sphereField(DVec3(0.0), 0.6),
                                 {layer(true, 0.15, "pink_frosting"), layer(true, 0, "chocolate"), layer(false, 0.1, "white_chocolate")}));
  return s;
}

}  // namespace

TEST_CASE("improveQuality: a 3-2 flip of three slivers around a short edge", "[solids]") {
  // Three tetrahedra around the long edge a-b through the middle of the triangle c-d-e:
  // quality 7.87 each (the ideal volume is a third of the whole). The two over and under
  // c-d-e are almost regular: 9.996.
  TetMesh m;
  m.positions = {{0, 0, 1.2}, {0, 0, -1.2}, {1, 0, 0}, {-0.5, 0.8660254037844386, 0}, {-0.5, -0.8660254037844386, 0}};
  m.tets = {{0, 1, 2, 3}, {0, 1, 3, 4}, {0, 1, 4, 2}};
  for (auto& t : m.tets)
    if (m.volume(size_t(&t - m.tets.data())) < 0) std::swap(t[2], t[3]);
  m.materials = {0, 0, 0};
  const double volume = m.volume(0) + m.volume(1) + m.volume(2);
  ImproveOptions opt;
  opt.collapses = false;
  opt.smoothing = false;
  const ImproveStats st = improveQuality(m, opt);
  CHECK(st.flips32 == 1);
  CHECK(st.flips23 == 0);
  REQUIRE(m.tets.size() == 2);
  CHECK(m.volume(0) + m.volume(1) == Approx(volume).epsilon(1e-12));
  // Both share the triangle 2-3-4, one with apex 0 and one with apex 1.
  for (const auto& t : m.tets) {
    CHECK(std::count(t.begin(), t.end(), 2u) + std::count(t.begin(), t.end(), 3u) + std::count(t.begin(), t.end(), 4u) == 3);
  }
  CHECK(st.before.minQuality == Approx(7.868).margin(1e-3));
  CHECK(st.after.minQuality == Approx(9.996).margin(1e-3));
  checkValid(m);
}

TEST_CASE("improveQuality: a 2-3 flip of two tetrahedra over a wide face", "[solids]") {
  // Two tetrahedra over and under the long triangle c-d-e, one of them flat (quality 5.53
  // and 2.44, the ideal volume half of the whole); the three around the edge a-b, which
  // pierces c-d-e, score 6.91, 4.85 and 4.49 (computed independently of Sprig).
  TetMesh m;
  m.positions = {{0.38, 0.31, 0.48}, {0.1, 0.04, -0.06}, {0.07, 0.5, 0}, {0.64, -0.05, 0}, {-0.89, -0.84, 0}};
  m.tets = {{2, 3, 4, 0}, {2, 4, 3, 1}};
  for (auto& t : m.tets)
    if (m.volume(size_t(&t - m.tets.data())) < 0) std::swap(t[2], t[3]);
  m.materials = {0, 0};
  REQUIRE(m.volume(0) > 0);
  REQUIRE(m.volume(1) > 0);
  ImproveOptions opt;
  opt.collapses = false;
  opt.smoothing = false;
  const ImproveStats st = improveQuality(m, opt);
  CHECK(st.flips23 == 1);
  REQUIRE(m.tets.size() == 3);
  for (const auto& t : m.tets) CHECK((std::count(t.begin(), t.end(), 0u) == 1 && std::count(t.begin(), t.end(), 1u) == 1));
  CHECK(st.before.minQuality == Approx(2.4405).margin(1e-3));
  CHECK(st.after.minQuality == Approx(4.4917).margin(1e-3));
  checkValid(m);
}

TEST_CASE("improveQuality: a 2-2 flip of two tetrahedra under a flat visible quadrilateral", "[solids]") {
  // The long diagonal a-b of the flat rhombus a-c-b-d (z = 0) under the apex x: two flat
  // tetrahedra of quality 6.18. The short diagonal c-d gives two of 7.49 (computed
  // independently of Sprig); the visible faces stay in the plane.
  TetMesh m;
  m.positions = {{-1, 0, 0}, {1, 0, 0}, {0, -0.3, 0}, {0, 0.3, 0}, {0, 0, 0.8}};
  m.tets = {{0, 1, 2, 4}, {0, 1, 3, 4}};
  for (auto& t : m.tets)
    if (m.volume(size_t(&t - m.tets.data())) < 0) std::swap(t[2], t[3]);
  m.materials = {0, 0};
  ImproveOptions opt;
  opt.collapses = false;
  opt.smoothing = false;
  const ImproveStats st = improveQuality(m, opt);
  CHECK(st.flips22 == 1);
  CHECK(st.flips23 + st.flips32 == 0);
  REQUIRE(m.tets.size() == 2);
  CHECK(st.before.minQuality == Approx(6.175).margin(1e-3));
  CHECK(st.after.minQuality == Approx(7.490).margin(1e-3));
  for (const auto& t : m.tets) CHECK((std::count(t.begin(), t.end(), 2u) == 1 && std::count(t.begin(), t.end(), 3u) == 1));
  CHECK(m.volume(0) + m.volume(1) == Approx(0.16).epsilon(1e-12));
  // The visible faces in z = 0 now split the rhombus along c-d; their area is unchanged.
  double flat = 0;
  for (const auto& t : visibleInterface(m)) {
    bool inPlane = true;
    for (uint32_t v : t.v) inPlane = inPlane && m.positions[v].z == 0;
    if (!inPlane) continue;
    flat += 0.5 * glm::length(glm::cross(m.positions[t.v[1]] - m.positions[t.v[0]], m.positions[t.v[2]] - m.positions[t.v[0]]));
    CHECK((std::count(t.v.begin(), t.v.end(), 2u) == 1 && std::count(t.v.begin(), t.v.end(), 3u) == 1));
  }
  CHECK(flat == Approx(0.6).epsilon(1e-12));
  checkValid(m);
}

TEST_CASE("improveQuality: flips, collapses and smoothing keep every interface and raise the quality", "[solids]") {
  TetMesh m = meshSolid(layeredSphere(), test::gridAround(0.8, 0.08));
  const auto volumes = volumeByMaterial(m);
  const auto areas = interfaceAreas(m);
  const ImproveStats st = improveQuality(m);
  INFO("quality min " << st.before.minQuality << " -> " << st.after.minQuality << ", mean " << st.before.meanQuality
                      << " -> " << st.after.meanQuality << "; tetrahedra " << st.tetsBefore << " -> " << st.tetsAfter << "; "
                      << st.flips23 << " 2-3, " << st.flips32 << " 3-2, " << st.collapses << " collapses, " << st.moves
                      << " moves");
  CHECK(st.flips23 > 0);
  CHECK(st.flips32 > 0);
  CHECK(st.collapses > 0);
  CHECK(st.moves > 0);
  CHECK(st.after.minQuality > st.before.minQuality);
  CHECK(st.after.meanQuality > st.before.meanQuality);
  CHECK(st.tetsAfter < st.tetsBefore);
  CHECK(st.tetsAfter == m.tets.size());
  CHECK(measureQuality(m, st.tetsBefore).minQuality == st.after.minQuality);
  checkValid(m);
  // With no tolerance an interface moves only where it is flat: each material keeps its
  // volume and each interface its area.
  const auto after = volumeByMaterial(m);
  REQUIRE(after.size() == volumes.size());
  for (const auto& [mat, vol] : volumes) CHECK(after.at(mat) == Approx(vol).epsilon(1e-9));
  const auto areasAfter = interfaceAreas(m);
  REQUIRE(areasAfter.size() == areas.size());
  for (const auto& [pair, area] : areas) CHECK(areasAfter.at(pair) == Approx(area).epsilon(1e-9));
}

TEST_CASE("improveQuality: a tolerance lets curved interfaces move that far and no further", "[solids]") {
  const double cell = 0.08;
  const TetMesh original = meshSolid(layeredSphere(), test::gridAround(0.8, cell));
  const auto volumes = volumeByMaterial(original);
  const auto areas = interfaceAreas(original);
  TetMesh exact = original, loose = original;
  const ImproveStats e = improveQuality(exact);
  ImproveOptions opt;
  opt.interfaceTolerance = 0.1 * cell;
  const ImproveStats l = improveQuality(loose, opt);
  INFO("collapses exact " << e.collapses << ", tolerant " << l.collapses << "; tetrahedra " << e.tetsAfter << " vs "
                          << l.tetsAfter << "; min quality " << e.after.minQuality << " vs " << l.after.minQuality);
  CHECK(l.collapses > e.collapses);
  CHECK(l.tetsAfter < e.tetsAfter);
  CHECK(l.after.minQuality > e.after.minQuality);
  checkValid(loose);
  // A material's volume changes by at most the tolerance times the area of its interfaces
  // (each interface point moves at most that far), and does change: the sphere is curved.
  const auto after = volumeByMaterial(loose);
  bool changed = false;
  for (const auto& [mat, vol] : volumes) {
    double bounding = 0;
    for (const auto& [pair, area] : areas)
      if (pair.first == mat || pair.second == mat) bounding += area;
    CHECK(std::abs(after.at(mat) - vol) <= opt.interfaceTolerance * bounding);
    changed = changed || std::abs(after.at(mat) - vol) > 1e-9 * vol;
  }
  CHECK(changed);
}

TEST_CASE("improveQuality: the same bytes at 1 and 2 threads", "[solids]") {
  const Solid s = layeredSphere();
  const Grid g = test::gridAround(0.8, 0.1);
  ImproveOptions opt;
  opt.interfaceTolerance = 0.005;
  std::string one, two;
  {
    ThreadLimit limit(1);
    TetMesh m = meshSolid(s, g);
    improveQuality(m, opt);
    one = formatTetMesh(m, s.materials.materials, TetFormat::Msh);
  }
  {
    ThreadLimit limit(2);
    TetMesh m = meshSolid(s, g);
    improveQuality(m, opt);
    two = formatTetMesh(m, s.materials.materials, TetFormat::Msh);
  }
  CHECK(one.size() > 10000);
  CHECK(one == two);
}
