#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/mesh.h"
#include "core/mesh_clean.h"
#include "core/parallel.h"
#include "solids/distance_field.h"
#include "solids/octree.h"
#include "solids/solid.h"
#include "lsystem/expression.h"
#include "solids/tet_io.h"
#include "tests/scratch_dir.h"
#include "tests/solids/grid_fixture.h"
#include "tests/solids/tet_checks.h"

using namespace sprig;
using namespace sprig::solids;
using test::faceUses;
using test::meshOf;
using test::volumeByMaterial;

namespace {

/// A solid of one sphere: layers given as (interior?, thickness or 0 = fill, material name).
struct LayerText {
  bool interior;
  double thickness;  // 0 = fill
  const char* material;
};

Solid sphereSolid(double radius, const std::vector<LayerText>& layers, DVec3 center = DVec3(0.0)) {
  Solid s;
  std::vector<Layer> ls;
  for (const LayerText& t : layers) {
    Layer l;
    l.interior = t.interior;
    l.fill = t.thickness == 0;
    l.thickness = t.thickness == 0 ? 1.0 : t.thickness;
    l.material = std::string(t.material) == "nothing" ? kNothing : *s.materials.concrete(t.material);
    ls.push_back(l);
  }
  s.volumes.push_back(makeVolume(sphereField(center, radius), ls));
  return s;
}

using test::gridAround;

double ballVolume(double r) { return 4.0 / 3.0 * M_PI * r * r * r; }

}  // namespace

TEST_CASE("meshSolid: a layered sphere", "[solids]") {
  // Pink frosting 0.15 inward from r = 0.6, chocolate filling the rest, white chocolate 0.1 outward.
  const double cell = 0.05;
  Solid s = sphereSolid(0.6, {{true, 0.15, "pink_frosting"}, {true, 0, "chocolate"}, {false, 0.1, "white_chocolate"}});
  MeshStats st;
  const TetMesh m = meshSolid(s, gridAround(0.8, cell), {}, &st);
  INFO("tets " << m.tets.size() << ", splits " << st.splits);
  REQUIRE(m.tets.size() > 1000);

  SECTION("tetrahedron volumes sum to the volumes the layers enclose") {
    // The mesh interpolates the exact distance linearly in each tetrahedron (diameter at
    // most cell·√3); |p| has Hessian norm 1/r, so an interface moves inward by at most
    // 3·cell²/(8·r), and snapping moves it by at most 0.05·cell.
    const auto vol = volumeByMaterial(m);
    double inside = 0;
    for (const auto& [name, r] : std::vector<std::pair<const char*, double>>{{"chocolate", 0.45}, {"pink_frosting", 0.6}, {"white_chocolate", 0.7}}) {
      inside += vol.at(uint16_t(*s.materials.concrete(name)));
      const double delta = 3 * cell * cell / (8 * r) + 0.05 * cell;
      INFO(name << ": volume inside r = " << r << " is " << inside << ", exact " << ballVolume(r) << ", bound ±" << delta << " in r");
      CHECK(inside >= ballVolume(r - delta));
      CHECK(inside <= ballVolume(r + delta));
    }
  }
  SECTION("measured layer thicknesses equal the specified ones within one cell") {
    // Radii of the vertices on each interface: the visible one (0.7), white | frosting (0.6),
    // frosting | chocolate (0.45).
    std::map<std::pair<int, int>, std::pair<double, double>> radii;  // material pair -> min, max radius
    auto note = [&](int a, int b, uint32_t v) {
      const double r = glm::length(m.positions[v]);
      auto [it, fresh] = radii.emplace(std::make_pair(std::min(a, b), std::max(a, b)), std::make_pair(r, r));
      it->second.first = std::min(it->second.first, r);
      it->second.second = std::max(it->second.second, r);
    };
    for (const auto& t : visibleInterface(m))
      for (uint32_t v : t.v) note(t.material, -1, v);
    const auto inner = materialInterfaces(m);
    std::map<std::array<uint32_t, 3>, int> firstSide;
    for (const auto& t : inner) {
      std::array<uint32_t, 3> k = t.v;
      std::sort(k.begin(), k.end());
      auto [it, fresh] = firstSide.emplace(k, t.material);
      if (!fresh)
        for (uint32_t v : t.v) note(it->second, t.material, v);
    }
    const int choc = *s.materials.concrete("chocolate"), pink = *s.materials.concrete("pink_frosting"),
              white = *s.materials.concrete("white_chocolate");
    const auto outer = radii.at({-1, white}), mid = radii.at({std::min(pink, white), std::max(pink, white)}),
               core = radii.at({std::min(choc, pink), std::max(choc, pink)});
    INFO("radii: outer " << outer.first << ".." << outer.second << ", mid " << mid.first << ".." << mid.second << ", core "
                         << core.first << ".." << core.second);
    CHECK(outer.first > 0.7 - cell);
    CHECK(outer.second < 0.7 + cell);
    CHECK(mid.first > 0.6 - cell);
    CHECK(mid.second < 0.6 + cell);
    CHECK(core.first > 0.45 - cell);
    CHECK(core.second < 0.45 + cell);
    // Thickness = difference of mean radii, within one cell of 0.1 and 0.15.
    CHECK(std::abs((outer.first + outer.second) / 2 - (mid.first + mid.second) / 2 - 0.1) < cell);
    CHECK(std::abs((mid.first + mid.second) / 2 - (core.first + core.second) / 2 - 0.15) < cell);
  }
  SECTION("no tetrahedron is inverted or flat") {
    double minVolume = 1e30;
    for (size_t t = 0; t < m.tets.size(); ++t) minVolume = std::min(minVolume, m.volume(t));
    INFO("smallest volume " << minVolume);
    CHECK(minVolume > 0);
  }
  SECTION("every face is shared by one or two tetrahedra, and the boundary is closed") {
    const auto uses = faceUses(m);
    CHECK(uses[2] == 0);
    size_t bad = 99;
    const auto vis = visibleInterface(m, &bad);
    CHECK(bad == 0);
    CHECK(vis.size() == uses[0]);
    const MeshTopology top = analyzeTopology(meshOf(m, vis));
    CHECK(top.closed());
    CHECK(top.manifold());
  }
}


TEST_CASE("meshSolid: precedence", "[solids]") {
  // Sphere A (nut, r 0.5 at -0.2 x) claims first; sphere B (chocolate, r 0.6 at +0.3 x) fills what is left.
  const double cell = 0.05, ra = 0.5, rb = 0.6, d = 0.5;
  Solid s;
  Layer nut, choc;
  nut.fill = choc.fill = true;
  nut.material = *s.materials.concrete("nut");
  choc.material = *s.materials.concrete("chocolate");
  s.volumes.push_back(makeVolume(sphereField(DVec3(-0.2, 0, 0), ra), {nut}));
  s.volumes.push_back(makeVolume(sphereField(DVec3(0.3, 0, 0), rb), {choc}));
  Grid g;
  g.cell = cell;
  g.origin = DVec3(-0.8, -0.7, -0.7);
  g.cells = {34, 28, 28};
  const TetMesh m = meshSolid(s, g);
  const auto vol = volumeByMaterial(m);
  // Exact: A, and B minus the lens A ∩ B.
  const double lens = M_PI * std::pow(ra + rb - d, 2) * (d * d + 2 * d * rb - 3 * rb * rb + 2 * d * ra + 6 * rb * ra - 3 * ra * ra) / (12 * d);
  const double exactA = ballVolume(ra), exactB = ballVolume(rb) - lens;
  const double tolerance = 4 * M_PI * 0.6 * 0.6 * (3 * cell * cell / (8 * ra) + 0.05 * cell);  // area · interface shift
  INFO("nut " << vol.at(uint16_t(nut.material)) << " (exact " << exactA << "), chocolate " << vol.at(uint16_t(choc.material))
              << " (exact " << exactB << "), tolerance " << tolerance);
  CHECK(std::abs(vol.at(uint16_t(nut.material)) - exactA) < tolerance);
  CHECK(std::abs(vol.at(uint16_t(choc.material)) - exactB) < tolerance);
  // No overlap and no gap: the total is the union's volume, faces match, the outside is closed.
  CHECK(std::abs(vol.at(uint16_t(nut.material)) + vol.at(uint16_t(choc.material)) - (exactA + exactB)) < 2 * tolerance);
  const auto uses = faceUses(m);
  CHECK(uses[2] == 0);
  const MeshTopology top = analyzeTopology(meshOf(m, visibleInterface(m)));
  CHECK(top.closed());
  CHECK(top.manifold());
  for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
}

namespace {

/// A closed octahedron of radius r as a polygon mesh (counter-clockwise seen from outside).
PolyMesh octahedron(float r) {
  PolyMesh p;
  p.positions = {{r, 0, 0}, {-r, 0, 0}, {0, r, 0}, {0, -r, 0}, {0, 0, r}, {0, 0, -r}};
  const uint32_t f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& t : f) {
    p.faceSizes.push_back(3);
    p.faceVertices.insert(p.faceVertices.end(), t, t + 3);
  }
  return p;
}

Solid octahedronSolid() {
  Solid s;
  Layer core, coat;
  core.fill = true;
  core.material = *s.materials.concrete("stone");
  coat.interior = false;
  coat.thickness = 0.1;
  coat.material = *s.materials.concrete("dirt");
  s.volumes.push_back(makeVolume(meshField(octahedron(0.6f)), {core, coat}));
  return s;
}

}  // namespace

TEST_CASE("meshSolid: a sealed pocket under one cell is filled, a larger one stays", "[solids]") {
  // A chocolate ball (r 0.6) with a spherical hole around a grid node: radius 0.03 puts the
  // node alone outside, and the cuts leave a pocket of 0.64 cell³ around it; radius 0.15 a
  // pocket of about 0.014 = 110 cell³.
  const double cell = 0.05;
  const DVec3 at(0.1, 0.0, 0.05);  // a node of gridAround(0.8, 0.05)
  auto holed = [&](double hole, MeshStats& st) {
    Solid s;
    Layer choc;
    choc.fill = true;
    choc.material = *s.materials.concrete("chocolate");
    s.volumes.push_back(makeVolume(subtractionField(sphereField(DVec3(0.0), 0.6), sphereField(at, hole)), {choc}));
    return meshSolid(s, gridAround(0.8, cell), {}, &st);
  };
  auto facesNearHole = [&](const TetMesh& m, double reach) {
    size_t n = 0;
    for (const auto& t : visibleInterface(m))
      n += glm::length(m.positions[t.v[0]] - at) < reach;
    return n;
  };
  MeshStats small, large;
  const TetMesh ms = holed(0.03, small), ml = holed(0.15, large);
  INFO("sealed specks filled: small hole " << small.sealedSpecks << ", large hole " << large.sealedSpecks);
  CHECK(small.sealedSpecks == 1);
  CHECK(facesNearHole(ms, 0.1) == 0);  // no surface left inside the ball
  size_t filled = 0;
  for (size_t t = 0; t < ms.tets.size(); ++t) {
    DVec3 c(0.0);
    for (uint32_t v : ms.tets[t]) c += ms.positions[v] * 0.25;
    if (glm::length(c - at) < 0.02) {
      ++filled;
      CHECK(ms.materials[t] == uint16_t(*Solid().materials.concrete("chocolate")));
    }
  }
  CHECK(filled > 0);
  CHECK(large.sealedSpecks == 0);
  CHECK(facesNearHole(ml, 0.2) > 100);  // the hole's wall stays
}

TEST_CASE("distance fields", "[solids]") {
  SECTION("primitives are Euclidean distances") {
    const std::vector<Vec3> pts = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 0.25f, 0}};
    const auto box = boxField(DVec3(0.0), DVec3(2, 1, 1))->sample(pts, 0.1, 1);
    CHECK(box[0] == Approx(-0.5));
    CHECK(box[1] == Approx(1.0));
    CHECK(box[2] == Approx(std::sqrt(1.0 + 1.5 * 1.5)));
    const auto cyl = cylinderField(DVec3(0.0), 0.5, 1.0, DVec3(0, 1, 0))->sample(pts, 0.1, 1);
    CHECK(cyl[0] == Approx(-0.5));
    CHECK(cyl[1] == Approx(1.5));
    CHECK(cyl[3] == Approx(-0.25));
    const auto plane = groundPlaneField(DVec3(0, 1, 0), 0.25)->sample(pts, 0.1, 1);
    CHECK(plane[2] == Approx(1.75));
    CHECK(plane[3] == Approx(0.0).margin(1e-7));
    const auto sub = subtractionField(boxField(DVec3(0.0), DVec3(2, 1, 1)), sphereField(DVec3(0.0), 0.2))->sample(pts, 0.1, 1);
    CHECK(sub[0] == Approx(0.2));
    const auto scaled = transformField(sphereField(DVec3(0.0), 1), 2.0, DVec3(0, 0, 1), 90, DVec3(0, 0, 0))->sample(pts, 0.1, 1);
    CHECK(scaled[1] == Approx(0.0).margin(1e-6));
  }
  SECTION("a closed mesh: negative inside, the distance to its faces near them") {
    const std::vector<Vec3> pts = {{0, 0, 0}, {0.5f, 0, 0}, {0.8f, 0, 0}, {3, 3, 3}};
    const auto d = meshField(octahedron(0.6f))->sample(pts, 0.02, 0.2);
    CHECK(d[0] < 0);  // deep inside: clamped to -band
    CHECK(d[1] == Approx(-0.1 / std::sqrt(3.0)).margin(0.01));
    CHECK(d[2] == Approx(0.2).margin(0.01));  // nearest: the vertex (0.6, 0, 0)
    CHECK(d[3] > 0);
  }
  SECTION("an offset grows a field: its value less the offset, its box wider, its child's band wider") {
    const FieldPtr grown = offsetField(meshField(octahedron(0.6f)), 0.1);
    const auto d = grown->sample({{0.5f, 0, 0}, {0.8f, 0, 0}, {0.88f, 0, 0}}, 0.02, 0.2);
    CHECK(d[0] == Approx(-0.1 / std::sqrt(3.0) - 0.1).margin(0.01));
    CHECK(d[1] == Approx(0.1).margin(0.01));
    // 0.28 from the mesh: within the child's band 0.2 + 0.1, not clamped (at band 0.2 it is 0.22)
    CHECK(d[2] == Approx(0.18).margin(0.01));
    const std::optional<DBox3> box = grown->bounds();
    REQUIRE(box);
    CHECK(box->lo.x == Approx(-0.7));
    CHECK(box->hi.y == Approx(0.7));
    CHECK(offsetField(sphereField(DVec3(0.0), 1), 0.0)->sample({{2, 0, 0}}, 0.1, 1)[0] == Approx(1.0));
    CHECK_THROWS_AS(offsetField(sphereField(DVec3(0.0), 1), -0.1), std::invalid_argument);
  }
  SECTION("the first open edge of a mesh") {
    PolyMesh p = octahedron(1);
    CHECK_FALSE(firstOpenEdge(p));
    p.faceSizes.pop_back();
    p.faceVertices.resize(p.faceVertices.size() - 3);
    const auto open = firstOpenEdge(p);
    REQUIRE(open);
    CHECK(open->face == 3);  // {3, 0, 4}: its edge 3-0 lost the face {0, 3, 5}
    CHECK(((open->a == 3 && open->b == 0)));
  }
}

TEST_CASE("meshSolid: the same bytes at 1 and 2 threads", "[solids]") {
  Solid s = octahedronSolid();
  const Grid g = gridAround(0.8, 0.04);
  std::string one, two;
  {
    ThreadLimit limit(1);
    one = formatTetMesh(meshSolid(s, g), s.materials.materials, TetFormat::Msh);
  }
  {
    ThreadLimit limit(2);
    two = formatTetMesh(meshSolid(s, g), s.materials.materials, TetFormat::Msh);
  }
  CHECK(one.size() > 10000);
  CHECK(one == two);
  MeshOptions coarse;
  coarse.coarsenLevels = 3;
  {
    ThreadLimit limit(1);
    one = formatTetMesh(meshSolid(s, g, coarse), s.materials.materials, TetFormat::Msh);
  }
  {
    ThreadLimit limit(2);
    two = formatTetMesh(meshSolid(s, g, coarse), s.materials.materials, TetFormat::Msh);
  }
  CHECK(one.size() > 10000);
  CHECK(one == two);
}

namespace {

/// Runs a shell command, returning its exit code and output.
std::pair<int, std::string> run(const std::string& command) {
  std::string out;
  FILE* p = ::popen((command + " 2>&1").c_str(), "r");
  REQUIRE(p);
  char buf[4096];
  while (size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  const int status = ::pclose(p);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace

TEST_CASE("writeTetMesh: Gmsh reads the .msh back with its materials", "[solids]") {
  // gmsh is installed by scripts/install-deps.sh (the test set-up).
  Solid s = octahedronSolid();
  const TetMesh m = meshSolid(s, gridAround(0.8, 0.05));
  sprig::test::TempDir dir("solids-gmsh");
  const auto msh = dir.path / "octa.msh";
  writeTetMesh(m, s.materials.materials, msh);
  SECTION("gmsh -check finds no error and counts our elements") {
    const auto [code, out] = run("gmsh -check '" + msh.string() + "'");
    INFO(out.substr(0, 3000));
    CHECK(code == 0);
    CHECK(out.find("Error") == std::string::npos);
    CHECK(out.find(std::to_string(m.tets.size()) + " elements") != std::string::npos);
  }
  SECTION("re-exported as MSH 2.2 it keeps one physical group per material") {
    const auto again = dir.path / "again.msh";
    const auto [code, out] = run("gmsh '" + msh.string() + "' -0 -format msh22 -o '" + again.string() + "'");
    INFO(out.substr(0, 3000));
    REQUIRE(code == 0);
    const std::string text = readFile(again);
    CHECK(text.find("$PhysicalNames\n2\n3 1 \"stone\"\n3 2 \"dirt\"\n") != std::string::npos);
    // Elements (only those of physical groups are saved): tetrahedra (type 4) per physical tag.
    std::istringstream in(text.substr(text.find("$Elements")));
    std::string tag;
    size_t n = 0;
    in >> tag >> n;
    std::map<int, size_t> perPhysical;
    for (size_t i = 0; i < n; ++i) {
      int id, type, ntags, physical, entity;
      in >> id >> type >> ntags >> physical >> entity;
      for (int k = 2; k < ntags; ++k) in >> entity;
      const int nodes = type == 4 ? 4 : type == 2 ? 3 : type == 1 ? 2 : 1;
      for (int k = 0; k < nodes; ++k) in >> entity;
      if (type == 4) ++perPhysical[physical];
    }
    size_t stone = 0;
    for (uint16_t k : m.materials) stone += k == 0;
    CHECK(perPhysical[1] == stone);
    CHECK(perPhysical[2] == m.tets.size() - stone);
  }
  SECTION("VTU and Medit hold the same counts") {
    const std::string vtu = formatTetMesh(m, s.materials.materials, TetFormat::Vtu);
    CHECK(vtu.find("NumberOfPoints=\"" + std::to_string(m.positions.size()) + "\" NumberOfCells=\"" +
                   std::to_string(m.tets.size()) + "\"") != std::string::npos);
    const std::string medit = formatTetMesh(m, s.materials.materials, TetFormat::Medit);
    CHECK(medit.find("Tetrahedra\n" + std::to_string(m.tets.size()) + "\n") != std::string::npos);
    CHECK(medit.substr(medit.size() - 4) == "End\n");
  }
}

TEST_CASE("measureQuality: the paper's metric", "[solids]") {
  // A regular tetrahedron: the largest smallest solid angle, 0.551 sr, so A = 10.
  const DVec3 a(1, 1, 1), b(1, -1, -1), c(-1, 1, -1), d(-1, -1, 1);
  CHECK(minSolidAngle(a, b, c, d) == Approx(0.5513).epsilon(1e-3));
  TetMesh one;
  one.positions = {a, b, d, c};
  one.tets = {{0, 1, 2, 3}};
  one.materials = {0};
  REQUIRE(one.volume(0) > 0);
  CHECK(measureQuality(one).minQuality == Approx(10));
  // A sliver scores low.
  TetMesh flat = one;
  flat.positions[3] = DVec3(0, 0, 0.05);
  flat.positions[2] = DVec3(-1, -1, 0.0);
  const QualityStats q = measureQuality(flat, 1);
  CHECK(q.minQuality < 7);
}

TEST_CASE("meshSolid: tetrahedra of a procedural layer follow the procedure", "[solids]") {
  // A sphere whose outer layer is striped by x > 0.1: after subdivision every tetrahedron of
  // the layer lies on one side of the plane (within the 5% snap of an edge).
  Solid s;
  ProceduralMaterial stripes;
  stripes.name = "stripes";
  stripes.select = lsystem::Expression::compile("x > 0.1", {"x", "y", "z"}, SourceLoc{"t", 1, 1});
  stripes.choices = {*s.materials.concrete("chocolate"), *s.materials.concrete("white_chocolate")};
  s.materials.procedural.push_back(stripes);
  Layer core, coat;
  core.fill = true;
  core.material = *s.materials.concrete("nut");
  coat.interior = false;
  coat.thickness = 0.15;
  coat.material = kProcedural0;
  s.volumes.push_back(makeVolume(sphereField(DVec3(0.0), 0.5), {core, coat}));
  const double cell = 0.05;
  const TetMesh m = meshSolid(s, gridAround(0.75, cell));
  size_t straddling = 0;
  for (size_t t = 0; t < m.tets.size(); ++t) {
    REQUIRE(m.volume(t) > 0);
    if (m.materials[t] == uint16_t(core.material)) continue;
    double lo = 1e9, hi = -1e9;
    for (uint32_t v : m.tets[t]) lo = std::min(lo, m.positions[v].x), hi = std::max(hi, m.positions[v].x);
    const bool white = m.materials[t] == uint16_t(stripes.choices[1]);
    // A tetrahedron on the wrong side by more than the snap distance of its edges.
    if ((white && lo < 0.1 - 0.05 * cell * 1.8) || (!white && hi > 0.1 + 0.05 * cell * 1.8)) ++straddling;
  }
  CHECK(straddling == 0);
  CHECK(faceUses(m)[2] == 0);
  CHECK(analyzeTopology(meshOf(m, visibleInterface(m))).closed());
}

TEST_CASE("smoothInterior: raises the worst quality, keeps every interface and each material's volume", "[solids]") {
  Solid s = sphereSolid(0.6, {{true, 0.15, "pink_frosting"}, {true, 0, "chocolate"}, {false, 0.1, "white_chocolate"}});
  TetMesh m = meshSolid(s, gridAround(0.8, 0.05));
  const TetMesh original = m;
  const auto volumes = volumeByMaterial(m);
  const SmoothStats st = smoothInterior(m);
  INFO("quality min " << st.before.minQuality << " -> " << st.after.minQuality << ", mean " << st.before.meanQuality << " -> "
                      << st.after.meanQuality << ", " << st.moved << " moves");
  CHECK(st.moved > 0);
  CHECK(st.after.minQuality > st.before.minQuality);
  CHECK(st.after.meanQuality > st.before.meanQuality);
  for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
  // The interfaces are where they were: the same triangles on the same positions.
  const auto before = visibleInterface(original), after = visibleInterface(m);
  REQUIRE(before.size() == after.size());
  for (size_t i = 0; i < before.size(); ++i)
    for (int c = 0; c < 3; ++c) REQUIRE(m.positions[after[i].v[c]] == original.positions[before[i].v[c]]);
  for (const auto& t : materialInterfaces(original))
    for (uint32_t v : t.v) REQUIRE(m.positions[v] == original.positions[v]);
  for (const auto& [mat, vol] : volumeByMaterial(m)) CHECK(vol == Approx(volumes.at(mat)).epsilon(1e-9));
}

namespace {

/// The tetrahedra of cellTetrahedra as a mesh on the unit lattice.
TetMesh latticeMesh(const Grid& g, const std::vector<std::array<uint32_t, 4>>& tets) {
  TetMesh m;
  for (const Vec3& p : gridNodes(g)) m.positions.push_back(DVec3(p));
  m.tets = tets;
  m.materials.assign(tets.size(), 0);
  return m;
}

double triangleArea(const TetMesh& m, const InterfaceTriangle& t) {
  return 0.5 * glm::length(glm::cross(m.positions[t.v[1]] - m.positions[t.v[0]], m.positions[t.v[2]] - m.positions[t.v[0]]));
}

}  // namespace

TEST_CASE("cellTetrahedra: a balanced octree meshes its leaves conforming", "[solids]") {
  Grid g;
  g.origin = DVec3(0.0);
  g.cell = 1;
  g.cells = {4, 4, 4};
  std::vector<uint64_t> cls(g.nodeCount(), 0);
  auto all = [](const uint32_t*) { return true; };
  CellStats st;
  SECTION("one class: a single leaf of five tetrahedra, or eight at one level less") {
    CHECK(cellTetrahedra(g, 2, cls, all, &st).size() == 5);
    CHECK(st.leaves == 1);
    CHECK(cellTetrahedra(g, 1, cls, all, &st).size() == 40);
    CHECK(st.leaves == 8);
    CHECK(st.transition == 0);
    CHECK(cellTetrahedra(g, 0, cls, all, &st).size() == 320);
  }
  SECTION("a mixed node keeps its cell fine; the leaves around it make the transition") {
    cls[0] = kMixedClass;  // node (0, 0, 0): cell (0, 0, 0) cannot merge, nor its 2x2x2 block
    const auto tets = cellTetrahedra(g, 2, cls, all, &st);
    // 8 cells of 5; the block across a corner is plain (5); the three across a face split it
    // (8 triangles) and meet the edges' midpoints on four faces (5 each): 30 each; the three
    // across an edge have its midpoint on two faces: 5 + 5 + 4·2 = 18 each.
    CHECK(st.leaves == 15);
    CHECK(st.coarseLeaves == 7);
    CHECK(st.transition == 6);
    CHECK(tets.size() == 40 + 5 + 3 * 30 + 3 * 18);
    const TetMesh m = latticeMesh(g, tets);
    double volume = 0, minVolume = 1e9;
    for (size_t t = 0; t < m.tets.size(); ++t) volume += m.volume(t), minVolume = std::min(minVolume, m.volume(t));
    CHECK(volume == Approx(64).epsilon(1e-12));
    CHECK(minVolume > 0);
    // Faces match: none is used by three tetrahedra and the unmatched ones are exactly the
    // box's six sides (a T-junction would leave unmatched faces inside).
    CHECK(faceUses(m)[2] == 0);
    double area = 0;
    for (const auto& t : visibleInterface(m)) area += triangleArea(m, t);
    CHECK(area == Approx(96).epsilon(1e-12));
    // The transition tetrahedra keep a bounded solid angle (a regular one has 0.551 sr).
    CHECK(measureQuality(m).minSolidAngle > 0.05);
  }
}

TEST_CASE("meshSolid: octree coarsening keeps the interfaces with fewer tetrahedra in the core", "[solids]") {
  // Fig. 4: the same distance field meshed on the uniform grid and on the coarsened octree.
  // A thin shell over a thick core: the core is where the octree coarsens.
  Solid s = sphereSolid(0.6, {{true, 0.05, "pink_frosting"}, {true, 0, "chocolate"}, {false, 0.05, "white_chocolate"}});
  const Grid g = gridAround(0.7, 0.025);
  MeshStats su, sc;
  const TetMesh uniform = meshSolid(s, g, {}, &su);
  MeshOptions opt;
  opt.coarsenLevels = 3;
  const TetMesh coarse = meshSolid(s, g, opt, &sc);
  INFO("uniform " << uniform.tets.size() << " tetrahedra, coarsened " << coarse.tets.size() << " (" << sc.coarseCubes
                  << " coarse leaves, " << sc.transitionCubes << " transition)");
  CHECK(sc.coarseCubes > 0);
  CHECK(coarse.tets.size() < uniform.tets.size());
  // The core (radius 22 cells), where no interface crosses, needs far fewer tetrahedra
  // (measured 56%: the 2:1 transition shells take most of so small a radius); the cut
  // tetrahedra at the interfaces are the same in both.
  const uint16_t core = uint16_t(*s.materials.concrete("chocolate"));
  auto count = [&](const TetMesh& m, bool inCore) {
    return size_t(std::count_if(m.materials.begin(), m.materials.end(), [&](uint16_t k) { return (k == core) == inCore; }));
  };
  INFO("core: uniform " << count(uniform, true) << ", coarsened " << count(coarse, true));
  CHECK(count(coarse, true) * 5 < count(uniform, true) * 3);
  // Interface tetrahedra are the same: each material's volume and the visible interface agree.
  const auto vu = volumeByMaterial(uniform), vc = volumeByMaterial(coarse);
  REQUIRE(vu.size() == vc.size());
  for (const auto& [mat, vol] : vu) CHECK(vc.at(mat) == Approx(vol).epsilon(1e-9));
  double au = 0, ac = 0;
  for (const auto& t : visibleInterface(uniform)) au += triangleArea(uniform, t);
  size_t bad = 99;
  const auto vis = visibleInterface(coarse, &bad);
  for (const auto& t : vis) ac += triangleArea(coarse, t);
  CHECK(ac == Approx(au).epsilon(1e-9));
  CHECK(bad == 0);
  CHECK(faceUses(coarse)[2] == 0);
  const MeshTopology top = analyzeTopology(meshOf(coarse, vis));
  CHECK(top.closed());
  CHECK(top.manifold());
  double minVolume = 1e9;
  for (size_t t = 0; t < coarse.tets.size(); ++t) minVolume = std::min(minVolume, coarse.volume(t));
  CHECK(minVolume > 0);
  // The same interface quality: the worst solid angle is an interface tetrahedron's in both.
  CHECK(measureQuality(coarse).minSolidAngle == Approx(measureQuality(uniform).minSolidAngle).epsilon(1e-9));
}

TEST_CASE("meshSolid: coarsening across interfaces where the fields are affine to a tolerance", "[solids]") {
  // §4.4: cells "accurately represented by interpolation" merge although an interface
  // crosses them. On a sphere of radius 0.6 (20 cells) a distance field departs from its
  // affine fit over a block of s cells by about s²/(8·20) cells: blocks of 2 and 4 pass a
  // tolerance of 0.1 cells, so less than half the tetrahedra remain (Fig. 4).
  Solid s = sphereSolid(0.6, {{true, 0.1, "pink_frosting"}, {true, 0, "chocolate"}, {false, 0.06, "white_chocolate"}});
  const double cell = 0.03;
  const Grid g = gridAround(0.72, cell);
  MeshStats su, sc;
  const TetMesh uniform = meshSolid(s, g, {}, &su);
  MeshOptions opt;
  opt.coarsenLevels = 3;
  opt.coarsenTolerance = 0.1;
  const TetMesh coarse = meshSolid(s, g, opt, &sc);
  INFO("uniform " << uniform.tets.size() << " tetrahedra, coarsened " << coarse.tets.size() << " (" << sc.coarseCubes
                  << " coarse leaves of " << sc.cubes << ")");
  CHECK(coarse.tets.size() * 2 < uniform.tets.size());
  test::checkValid(coarse);
  // Each interface moved by at most the tolerance: every material's volume is within the
  // tolerance times its surfaces' area of the uniform mesh's.
  const auto vu = volumeByMaterial(uniform), vc = volumeByMaterial(coarse);
  REQUIRE(vu.size() == vc.size());
  const double eps = opt.coarsenTolerance * cell;
  const double rIn = 0.5, rOut = 0.6, rWhite = 0.66;
  const std::map<std::string, double> area = {{"pink_frosting", 4 * M_PI * (rIn * rIn + rOut * rOut)},
                                              {"chocolate", 4 * M_PI * rIn * rIn},
                                              {"white_chocolate", 4 * M_PI * (rOut * rOut + rWhite * rWhite)}};
  for (const auto& [name, a] : area) {
    const uint16_t id = uint16_t(*s.materials.concrete(name));
    INFO(name);
    CHECK(std::abs(vc.at(id) - vu.at(id)) <= eps * a);
  }
  // With no tolerance the same grid keeps every interface tetrahedron of the uniform mesh.
  opt.coarsenTolerance = 0;
  const TetMesh exact = meshSolid(s, g, opt);
  for (const auto& [mat, vol] : volumeByMaterial(exact)) CHECK(vol == Approx(vu.at(mat)).epsilon(1e-9));
}

namespace {

/// Two bronze tetrahedra (material 0) that share the edge (0,0,0)-(0,0,1) only, on opposite
/// sides of it; with clay, a third tetrahedron (material 1) fills one of the two gaps
/// between them, so together they are one wedge.
TetMesh edgeContact(bool clay) {
  TetMesh m;
  m.positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0.5}, {0, 1, 0.5}, {-1, 0, 0.5}, {0, -1, 0.5}};
  m.tets = {{0, 1, 2, 3}, {0, 1, 4, 5}};
  m.materials = {0, 0};
  if (clay) {
    m.tets.push_back({0, 1, 3, 4});
    m.materials.push_back(1);
  }
  return m;
}

/// Two tetrahedra that share the vertex 0 only.
TetMesh vertexContact() {
  TetMesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  m.tets = {{0, 1, 2, 3}, {0, 5, 4, 6}};
  m.materials = {0, 0};
  return m;
}

Mesh meshOf(const BoundarySurface& s) {
  Mesh out;
  for (const DVec3& p : s.positions) out.positions.push_back(Vec3(p));
  for (const auto& t : s.triangles) out.triangles.push_back({t.v[0], t.v[1], t.v[2]});
  return out;
}

size_t componentsOf(const Mesh& m) {
  size_t n = 0;
  triangleComponents(m, &n);
  return n;
}

}  // namespace

TEST_CASE("boundarySurface: pieces touching along an edge are pulled apart into two sheets", "[solids]") {
  SECTION("an edge-only contact: four triangles at the edge in the visible interface, two sheets here") {
    const TetMesh m = edgeContact(false);
    for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
    const MeshTopology pinched = analyzeTopology(meshOf(m, visibleInterface(m)));
    CHECK(pinched.nonManifoldEdges == 1);
    const BoundarySurface s = boundarySurface(m);
    REQUIRE(s.triangles.size() == 8);
    CHECK(s.splitVertices == 2);
    CHECK(s.splitEdges == 0);
    CHECK(s.positions.size() == 8);  // 6 vertices, the edge's two each in two sheets
    const Mesh surface = meshOf(s);
    const MeshTopology topo = analyzeTopology(surface);
    CHECK(topo.closed());
    CHECK(topo.manifold());
    CHECK(componentsOf(surface) == 2);
    CHECK(signedVolume(surface) < m.volume(0) + m.volume(1));  // the copies moved inward
    CHECK(signedVolume(surface) == Approx(m.volume(0) + m.volume(1)).epsilon(1e-2));
    // Each copy of (0,0,0) moved 1e-3 of its shortest edge (the contact edge, length 1)
    // toward its own tetrahedron's centroid: (±0.25, ±0.25, 0.5) normalized.
    std::vector<DVec3> copies;
    for (size_t v = 0; v < s.positions.size(); ++v)
      if (s.sources[v][0] == 0) copies.push_back(s.positions[v]);
    REQUIRE(copies.size() == 2);
    const DVec3 towardA = glm::normalize(DVec3(0.25, 0.25, 0.5)), towardB = glm::normalize(DVec3(-0.25, -0.25, 0.5));
    CHECK(glm::length(copies[0] - 1e-3 * towardA) < 1e-12);
    CHECK(glm::length(copies[1] - 1e-3 * towardB) < 1e-12);
    // The vertices no sheet shares stay where they were, in ascending order.
    for (size_t v = 0; v < s.positions.size(); ++v)
      if (s.sources[v][0] >= 2) CHECK(s.positions[v] == m.positions[s.sources[v][0]]);
    for (size_t v = 0; v < s.positions.size(); ++v) CHECK(s.sources[v][0] == s.sources[v][1]);
    CHECK(std::is_sorted(s.sources.begin(), s.sources.end()));
  }
  SECTION("pull 0 keeps the copies in place, still two sheets by their ids") {
    const BoundarySurface s = boundarySurface(edgeContact(false), {}, 0.0);
    CHECK(s.splitVertices == 2);
    for (size_t v = 0; v < s.positions.size(); ++v) CHECK(s.positions[v] == edgeContact(false).positions[s.sources[v][0]]);
    CHECK(analyzeTopology(meshOf(s)).manifold());
    CHECK(componentsOf(meshOf(s)) == 2);
  }
}

TEST_CASE("boundarySurface: pieces touching at a vertex are pulled apart; one material's boundary", "[solids]") {
  SECTION("a vertex-only contact: one piece by its vertices in the visible interface, two here") {
    const TetMesh m = vertexContact();
    for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
    CHECK(componentsOf(meshOf(m, visibleInterface(m))) == 1);
    const BoundarySurface s = boundarySurface(m);
    CHECK(s.splitVertices == 1);
    CHECK(s.positions.size() == 8);
    const Mesh surface = meshOf(s);
    CHECK(analyzeTopology(surface).closed());
    CHECK(analyzeTopology(surface).manifold());
    CHECK(componentsOf(surface) == 2);
  }
  SECTION("one material's boundary: the clay closes the visible interface, the bronze alone still touches along the edge") {
    const TetMesh m = edgeContact(true);
    for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
    const BoundarySurface all = boundarySurface(m);
    CHECK(all.splitVertices == 0);
    CHECK(all.triangles.size() == 8);
    CHECK(analyzeTopology(meshOf(all)).closed());
    CHECK(analyzeTopology(meshOf(all)).manifold());
    const BoundarySurface bronze = boundarySurface(m, {1, 1, 0});
    CHECK(bronze.triangles.size() == 8);
    CHECK(bronze.splitVertices == 2);
    CHECK(analyzeTopology(meshOf(bronze)).closed());
    CHECK(analyzeTopology(meshOf(bronze)).manifold());
    CHECK(componentsOf(meshOf(bronze)) == 2);
    const BoundarySurface clay = boundarySurface(m, {0, 0, 1});
    CHECK(clay.triangles.size() == 4);
    CHECK(clay.splitVertices == 0);
  }
}

TEST_CASE("boundarySurface: split edges around a material between others; without contacts, the visible interface",
          "[solids]") {
  SECTION("material between others around an edge, joined around both ends: split edge") {
    // An octahedron around the edge (0,0,0)-(0,0,1): four tetrahedra, bronze (0) and clay
    // (1) in turn; bronze caps below and above join the two bronze wedges around each end.
    TetMesh m;
    m.positions = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0.5}, {0, 1, 0.5}, {-1, 0, 0.5}, {0, -1, 0.5}, {0, 0, -1}, {0, 0, 2}};
    for (uint32_t i = 0; i < 4; ++i) {
      const uint32_t p = 2 + i, q = 2 + (i + 1) % 4;
      m.tets.push_back({0, 1, p, q});
      m.materials.push_back(uint16_t(i % 2));
      m.tets.push_back({0, q, p, 6});
      m.materials.push_back(0);
      m.tets.push_back({1, p, q, 7});
      m.materials.push_back(0);
    }
    for (size_t t = 0; t < m.tets.size(); ++t)
      if (m.volume(t) < 0) std::swap(m.tets[t][2], m.tets[t][3]);
    for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
    std::vector<uint8_t> bronze(m.tets.size());
    for (size_t t = 0; t < bronze.size(); ++t) bronze[t] = m.materials[t] == 0;
    const BoundarySurface b = boundarySurface(m, bronze);
    // The bronze meets itself along the axis (the clay on both sides) and along each clay
    // tetrahedron's equator edge (its caps, the clay on one side, outside on the other), and
    // is joined around the ends of all three: each is split once.
    CHECK(b.splitVertices == 0);
    CHECK(b.splitEdges == 3);
    // The caps' 8 outer faces, the clay tetrahedra's 4 faces each, and 3 · 2 halves.
    CHECK(b.triangles.size() == 8 + 8 + 6);
    const Mesh surface = meshOf(b);
    const MeshTopology topo = analyzeTopology(surface);
    CHECK(topo.closed());
    CHECK(topo.manifold());
    CHECK(componentsOf(surface) == 1);
    double clay = 0, all = 0;
    for (size_t t = 0; t < m.tets.size(); ++t) (m.materials[t] == 1 ? clay : all) += m.volume(t);
    CHECK(signedVolume(surface) == Approx(all).epsilon(1e-2));
    // The midpoint vertex stands for the edge's ends, 1e-3 of its shortest edge (0.5) from
    // the midpoint, into its wedge (the bronze tetrahedron between (-1,0,.5) and (0,-1,.5)).
    const auto axis = std::find(b.sources.begin(), b.sources.end(), std::array<uint32_t, 2>{0, 1});
    REQUIRE(axis != b.sources.end());
    const DVec3 mid = b.positions[size_t(axis - b.sources.begin())];
    CHECK(glm::length(mid - DVec3(0, 0, 0.5)) == Approx(0.5e-3));
    CHECK(mid.x < 0);
    CHECK(mid.y < 0);
    // Every tetrahedron together: no contact.
    const BoundarySurface whole = boundarySurface(m);
    CHECK(whole.splitVertices + whole.splitEdges == 0);
    CHECK(analyzeTopology(meshOf(whole)).manifold());
    (void)clay;
  }
  SECTION("without contacts it is the visible interface, vertex for vertex") {
    Solid s = sphereSolid(0.6, {{true, 0.15, "pink_frosting"}, {true, 0, "chocolate"}, {false, 0.1, "white_chocolate"}});
    const TetMesh m = meshSolid(s, gridAround(0.8, 0.1));
    const std::vector<InterfaceTriangle> visible = visibleInterface(m);
    const BoundarySurface b = boundarySurface(m);
    REQUIRE(b.triangles.size() == visible.size());
    CHECK(b.splitVertices == 0);
    bool same = true;
    for (size_t t = 0; t < visible.size(); ++t)
      for (size_t c = 0; c < 3; ++c) same = same && b.sources[b.triangles[t].v[c]][0] == visible[t].v[c] && b.triangles[t].material == visible[t].material;
    CHECK(same);
    for (size_t v = 0; v < b.positions.size(); ++v) CHECK(b.positions[v] == m.positions[b.sources[v][0]]);
  }
}

TEST_CASE("meshSolid: a box whose faces lie on the grid's planes meshes whole, edges and corners straight", "[solids]") {
  // Every node on the box's faces has distance 0, so the tetrahedra spanning its convex
  // edges have all four vertices on the zero set: their linear centroid value is 0 and
  // cannot tell inside from outside. The box's own field at their centroids keeps them,
  // so the mesh is the box exactly (before, every other cell along each edge lost them).
  const double cell = 0.1;
  Solid s;
  Layer stone;
  stone.fill = true;
  stone.material = *s.materials.concrete("stone");
  s.volumes.push_back(makeVolume(boxField(DVec3(0.0), DVec3(0.6, 0.4, 0.8)), {stone}));
  Grid g;
  g.cell = cell;
  g.origin = DVec3(-0.5, -0.4, -0.6);
  g.cells = {10, 8, 12};
  const TetMesh m = meshSolid(s, g);
  const auto vol = volumeByMaterial(m);
  CHECK(std::abs(vol.at(uint16_t(stone.material)) - 0.6 * 0.4 * 0.8) < 1e-12);
  for (const DVec3& p : m.positions) {
    CHECK(std::abs(p.x) <= 0.3 + 1e-12);
    CHECK(std::abs(p.y) <= 0.2 + 1e-12);
    CHECK(std::abs(p.z) <= 0.4 + 1e-12);
  }
  // The visible interface is the box's six faces: every triangle lies in one face plane.
  const MeshTopology top = analyzeTopology(meshOf(m, visibleInterface(m)));
  CHECK(top.boundaryEdges == 0);
  for (const auto& f : visibleInterface(m)) {
    const DVec3 a = m.positions[f.v[0]], b = m.positions[f.v[1]], c = m.positions[f.v[2]];
    const bool onFace = (a.x == b.x && b.x == c.x) || (a.y == b.y && b.y == c.y) || (a.z == b.z && b.z == c.z);
    CHECK(onFace);
  }
}
