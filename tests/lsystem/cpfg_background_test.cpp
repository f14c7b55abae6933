// cpfg's background scene files (lsystem/cpfg_background.h): the reader's primitives,
// transforms and materials, the triangles drawn, and its errors.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>

#include "core/diagnostics.h"
#include "lsystem/cpfg_background.h"
#include "lsystem/view_file.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

constexpr const char* kGrey = "material\n0.1 0.1 0.1 1\n0.4 0.5 0.6 1\n0 0 0 1\n0 0 0 1\n1\n";

CpfgBackground scene(const std::string& text) {
  std::vector<Diagnostic> warnings;
  return parseCpfgBackground({text}, {"b.dat"}, warnings);
}

std::string errorOf(const std::string& text) {
  try {
    scene(text);
  } catch (const InputError& e) {
    const Diagnostic& d = e.diagnostics().front();
    return d.loc.file + ":" + std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) + ": " + d.message;
  }
  return "no error";
}

void checkNear(const DVec3& a, const DVec3& b) {
  INFO("got (" << a.x << ", " << a.y << ", " << a.z << "), expected (" << b.x << ", " << b.y << ", " << b.z << ")");
  CHECK(glm::length(a - b) < 1e-9 * (1 + glm::length(b)));
}

DVec3 apply(const glm::dmat4& m, const DVec3& p) { return DVec3(m * glm::dvec4(p, 1.0)); }

}  // namespace

TEST_CASE("parseCpfgBackground: primitives, transforms and materials", "[lsystem][cpfg][background]") {
  SECTION("vlab's BackgroundScene file: every primitive, its material") {
    const ViewFile v = loadViewFile(std::string(SPRIG_SOURCE_DIR) + "/tests/assets/cpfg/background/plant.v");
    REQUIRE(v.background);
    CHECK_FALSE(v.unsupportedDrawing);
    const CpfgBackground& b = *v.background;
    REQUIRE(b.materials.size() == 5);
    CHECK(b.materials[1].diffuse == Vec3(0.5f, 0.2f, 0.1f));
    CHECK(b.materials[0].alpha == 0.5f);  // '#define TR1 0.5'
    using K = CpfgBackgroundPrimitive::Kind;
    const std::vector<K> kinds = {K::Sphere, K::Cylinder, K::Polygon, K::Cylinder, K::Box, K::Cone, K::Polygon, K::Mesh, K::Sphere};
    REQUIRE(b.primitives.size() == kinds.size());
    for (size_t k = 0; k < kinds.size(); ++k) CHECK(b.primitives[k].kind == kinds[k]);
    CHECK(b.primitives[5].material == 2);
    CHECK(b.primitives[8].material == 4);
    // Two translucent materials (TR1 0.5, the 0.4 one): a warning each.
    size_t translucent = 0;
    for (const Diagnostic& d : v.warnings) translucent += d.message.rfind("a translucent material", 0) == 0;
    CHECK(translucent == 3);  // TR1, 0.4 and TR3
    // Triangles: sphere 2208, cylinder 188, quad 2, cylinder 188, box 12, cone 188, quad 2, mesh 6, sphere 2208.
    const CpfgBackgroundMesh m = b.triangulate();
    CHECK(m.triangleMaterials.size() == 2208 + 188 + 2 + 188 + 12 + 188 + 2 + 6 + 2208);
    CHECK(m.triangles.size() == 3 * m.triangleMaterials.size());
  }
  SECTION("a translated, rotated, scaled sphere: its centre and radii") {
    const CpfgBackground b = scene(std::string(kGrey) + "pushmatrix\ntranslate 2 2 0\nrotate 45 1 1 0\nscale 2 1 1\nsphere 0.5\npopmatrix\nsphere 1\n");
    REQUIRE(b.primitives.size() == 2);
    const glm::dmat4& m = b.primitives[0].sceneFromLocal;
    checkNear(apply(m, DVec3(0)), DVec3(2, 2, 0));
    // Rotating x by 45 degrees about (1,1,0)/sqrt 2 (Rodrigues): (c + (1-c)/2, (1-c)/2, -s/sqrt 2).
    const double c = std::sqrt(0.5);
    const DVec3 rx(c + (1 - c) / 2, (1 - c) / 2, -0.5);
    checkNear(apply(m, DVec3(0.5, 0, 0)), DVec3(2, 2, 0) + 2 * 0.5 * rx);  // the long radius, 1
    checkNear(apply(m, DVec3(0, 0.5, 0)) - DVec3(2, 2, 0), 0.5 * DVec3((1 - c) / 2, c + (1 - c) / 2, 0.5));  // y, rotated
    CHECK(glm::length(DVec3(m[0])) == Approx(2.0));
    CHECK(glm::length(DVec3(m[1])) == Approx(1.0));
    CHECK(glm::length(DVec3(m[2])) == Approx(1.0));
    checkNear(apply(b.primitives[1].sceneFromLocal, DVec3(0)), DVec3(0));  // popmatrix restored the identity
    // The drawn sphere: its vertex at local (r, 0, 0) lies at the centre + 1 along rotated x.
    const CpfgBackgroundMesh mesh = b.triangulate();
    bool found = false;
    for (const DVec3& p : mesh.positions) found = found || glm::length(p - (DVec3(2, 2, 0) + rx)) < 1e-9;
    CHECK(found);
  }
  SECTION("a polygon after multmatrix (column by column, translation last)") {
    const CpfgBackground b = scene(std::string(kGrey) + "multmatrix\n0.7 0.7 0 0\n-0.7 0.7 0 0\n0 0 1 0\n1 3 0 1\npolygon -1 -1 0 -1 1 0 1 1 0 1 -1 0\n");
    const CpfgBackgroundMesh m = b.triangulate();
    REQUIRE(m.positions.size() == 4);
    REQUIRE(m.triangleMaterials.size() == 2);
    checkNear(m.positions[0], DVec3(1.0, 1.6, 0));
    checkNear(m.positions[1], DVec3(-0.4, 3.0, 0));
    checkNear(m.positions[2], DVec3(1.0, 4.4, 0));
    checkNear(m.positions[3], DVec3(2.4, 3.0, 0));
    for (const DVec3& n : m.normals) CHECK(std::abs(n.z) == Approx(1.0));
  }
  SECTION("rectangle, mesh, box, cylinder, cone: exact triangles and extents") {
    const CpfgBackground b = scene(std::string(kGrey) + "rectangle 2 3 1 1\nmesh 0 0 0 1 0 0 0 1 0 1 1 0 0 2 0 1 2 0\nbox 1 2 3\ncylinder 0.5 2\ncone 1 0 2\n");
    const CpfgBackgroundMesh m = b.triangulate();
    CHECK(m.triangleMaterials.size() == 2 + 4 + 12 + 188 + (96 + 46));  // a cone's zero top disc is not drawn
    checkNear(m.positions[2], DVec3(3, 4, 0));  // the rectangle's far corner
    DVec3 lo(1e9), hi(-1e9);
    for (size_t k = 4 + 8 + 24; k < m.positions.size(); ++k) {
      lo = glm::min(lo, m.positions[k]);
      hi = glm::max(hi, m.positions[k]);
    }
    checkNear(lo, DVec3(-1, 0, -1));
    checkNear(hi, DVec3(1, 2, 1));
  }
  SECTION("#define and /* */, as cpfg's preproc reads them (no space after a minus sign)") {
    const CpfgBackground b = scene("#define STEP 35\n#define GREY 0.5 0.5 0.5 1\nmaterial 0 0 0 1 GREY\ntranslate -STEP 0 0 /* a\ncomment */ sphere 1\n");
    REQUIRE(b.primitives.size() == 1);
    CHECK(b.materials[0].diffuse == Vec3(0.5f));
    checkNear(apply(b.primitives[0].sceneFromLocal, DVec3(0)), DVec3(-35, 0, 0));
  }
}

TEST_CASE("parseCpfgBackground: errors at file:line:col", "[lsystem][cpfg][background]") {
  const std::string g = kGrey;  // 6 lines
  CHECK(errorOf(g + "spere 1\n") == "b.dat:7:1: unknown background scene command 'spere' (did you mean 'sphere'?)");
  CHECK(errorOf("sphere 1\n") == "b.dat:1:1: a primitive before the first 'material' (cpfg draws it in the colour of its colour map's entry 256, which Sprig does not read)");
  CHECK(errorOf(g + "popmatrix\n") == "b.dat:7:1: 'popmatrix' without its 'pushmatrix'");
  CHECK(errorOf(g + "polygon 0 0 0 1 1 1\n") == "b.dat:7:1: 'polygon' expects 3 or more vertices (x y z each), got 6 numbers");
  CHECK(errorOf(g + " sphere x\n") == "b.dat:7:2: 'sphere' expects 1 number (the radius), got 0 numbers");
  CHECK(errorOf(g + "rectangle 1 1 0 0 2\n") == "b.dat:7:1: a rectangle's fifth number (a factor of its emission) is not supported");
  CHECK(errorOf(g + "rotate 30 0 0 0\n") == "b.dat:7:1: a rotation about the zero vector");
  CHECK(errorOf(g + "multmatrix 1 0 0 1 0 1 0 0 0 0 1 0 0 0 0 1\n") ==
        "b.dat:7:1: a projective 'multmatrix' (its numbers 4, 8, 12 and 16 not 0 0 0 1) is not supported");
  CHECK(errorOf("#include \"a.dat\"\n") == "b.dat:1:1: C preprocessor directive '#include' in a background scene file is not supported");
  CHECK(errorOf("#define F(x) x\n") == "b.dat:1:1: only '#define NAME text' (a macro without parameters) is supported in a background scene file");
  CHECK(errorOf("/* open\n") == "b.dat:1:1: unterminated comment '/*'");
  // cpfg's preproc removes no '//' comment: cpfg reads its words as unknown commands.
  CHECK(errorOf(g + "sphere 1 // note\n") == "b.dat:7:10: unknown background scene command '//'");
  CHECK(errorOf("1 2 3\n") == "b.dat:1:1: a number '1' where a background scene command goes");
  std::string deep = g;
  for (int k = 0; k < 50; ++k) deep += "pushmatrix\n";
  CHECK(errorOf(deep) == "b.dat:56:1: the matrix stack is full (49 pushmatrix deep, cpfg's limit)");
  CHECK(errorOf(g + "sphere 2e15\n") == "b.dat:7:8: a number beyond 1e15 in magnitude (Sprig's limit)");
  CHECK(errorOf(g + "scale 1e10 1 1 scale 1e10 1 1 sphere 1\n") == "b.dat:7:31: the transformation grows beyond 1e15 (Sprig's limit)");
  std::string spheres = g;
  for (int k = 0; k < 906; ++k) spheres += "sphere 1\n";  // 905 are 1,998,240 triangles
  CHECK(errorOf(spheres) == "b.dat:912:1: the background scene has more than 2000000 triangles (Sprig's limit)");
}

TEST_CASE("view file background scene: drawing errors wait for a drawing", "[lsystem][cpfg][background]") {
  const std::string dir = std::string(SPRIG_SOURCE_DIR) + "/tests/assets/cpfg/background";
  // A cylinder under the default (pixel) line style: cpfg draws it as a line.
  ViewFile pixel = parseViewFile("background scene: background.dat\n", dir + "/t.v");
  REQUIRE(pixel.unsupportedDrawing);
  CHECK(pixel.unsupportedDrawing->loc.line == 14);
  CHECK(pixel.unsupportedDrawing->message ==
        "cpfg draws a background cylinder or cone in the line style of F; Sprig draws it only with 'line style: cylinder' (a solid)");
  ViewFile untapered = parseViewFile("line style: cylinder\ntapered lines: off\nbackground scene: background.dat\n", dir + "/t.v");
  REQUIRE(untapered.unsupportedDrawing);
  CHECK(untapered.unsupportedDrawing->loc.line == 52);
  ViewFile missing = parseViewFile("line style: cylinder\nbackground scene: none.dat\n", dir + "/t.v");
  REQUIRE(missing.unsupportedDrawing);
  CHECK(missing.unsupportedDrawing->loc.line == 2);
  ViewFile outside = parseViewFile("background scene: ../x.dat\n", dir + "/t.v");
  REQUIRE(outside.unsupportedDrawing);
  CHECK(outside.unsupportedDrawing->message ==
        "the background scene file '../x.dat' is outside the object's folder (only files beside the view file, or in folders below it)");
}

TEST_CASE("parseCpfgBackground: the geometry the real cpfg writes", "[lsystem][cpfg][background]") {
  // tests/assets/cpfg/background/cpfg.ray: cpfg's rayshade output for background.dat (its
  // README has the command). The stem is cpfg's first cylinder, of radius 0.05.
  const std::string dir = std::string(SPRIG_SOURCE_DIR) + "/tests/assets/cpfg/background";
  const ViewFile v = loadViewFile(dir + "/plant.v");
  REQUIRE(v.background);
  const CpfgBackground& b = *v.background;
  const CpfgBackgroundMesh mesh = b.triangulate();
  std::ifstream in(dir + "/cpfg.ray");
  std::vector<DVec3> corners;                   // of cpfg's triangles
  std::vector<std::pair<DVec3, DVec3>> tubes;   // cylinder and cone ends, after the stem
  std::vector<std::pair<DVec3, double>> spheres;
  for (std::string word; in >> word;) {
    std::string surface;
    if (word == "triangle")
      for (int k = 0; k < 3; ++k) {
        DVec3 p, n;
        in >> p.x >> p.y >> p.z >> n.x >> n.y >> n.z;
        corners.push_back(p);
      }
    if (word == "sphere") {
      double r;
      DVec3 c;
      in >> surface >> r >> c.x >> c.y >> c.z;
      spheres.emplace_back(c, r);
    }
    if (word == "cylinder" || word == "cone") {
      double r0, r1 = 0;
      DVec3 a, e;
      in >> surface >> r0 >> a.x >> a.y >> a.z;
      if (word == "cone") in >> r1;
      in >> e.x >> e.y >> e.z;
      if (surface != "s000") tubes.emplace_back(a, e);  // s000: the plant's stem
    }
  }
  REQUIRE(corners.size() == 3 * 22);  // two quads of polygons, a box, a mesh of three quads
  for (const DVec3& c : corners) {
    double nearest = 1e9;
    for (const DVec3& p : mesh.positions) nearest = std::min(nearest, glm::length(p - c));
    INFO("cpfg's corner (" << c.x << ", " << c.y << ", " << c.z << ")");
    CHECK(nearest < 2e-5);
  }
  using K = CpfgBackgroundPrimitive::Kind;
  std::vector<std::pair<DVec3, DVec3>> ours;
  std::vector<std::pair<DVec3, double>> ourSpheres;
  size_t flatTriangles = 0;
  for (const CpfgBackgroundPrimitive& p : b.primitives) {
    const DVec3 base = apply(p.sceneFromLocal, DVec3(0));
    if (p.kind == K::Cylinder) ours.emplace_back(base, apply(p.sceneFromLocal, DVec3(0, p.numbers[1], 0)));
    if (p.kind == K::Cone) ours.emplace_back(base, apply(p.sceneFromLocal, DVec3(0, p.numbers[2], 0)));
    if (p.kind == K::Sphere) ourSpheres.emplace_back(base, p.numbers[0]);
    if (p.kind == K::Polygon) flatTriangles += p.numbers.size() / 3 - 2;
    if (p.kind == K::Box) flatTriangles += 12;
    if (p.kind == K::Mesh) flatTriangles += p.numbers.size() / 3 - 2;
  }
  CHECK(flatTriangles == 22);
  // cpfg draws the opaque materials first, then the translucent ones: compare as sets.
  REQUIRE(tubes.size() == ours.size());
  for (const auto& t : tubes) {
    bool found = false;
    for (const auto& o : ours) found = found || (glm::length(o.first - t.first) < 2e-5 && glm::length(o.second - t.second) < 2e-5);
    INFO("cpfg's tube from (" << t.first.x << ", " << t.first.y << ", " << t.first.z << ")");
    CHECK(found);
  }
  REQUIRE(spheres.size() == 2);
  REQUIRE(ourSpheres.size() == 2);
  for (const auto& sp : spheres) {
    bool found = false;
    for (const auto& o : ourSpheres) found = found || (glm::length(o.first - sp.first) < 2e-5 && o.second == sp.second);
    CHECK(found);
  }
}
