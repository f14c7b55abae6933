// Every grammar shipped in grammars/ also runs as a cpfg `.l` file in a vlab object folder,
// grammars/vlab/NAME/ (NAME.l and, when the grammar has an angle, NAME.v). This test is the
// folders' generator and their check: each grammar is converted to cpfg's notation (the
// `angle:` header becomes the view file's `angle increment`, ABOP's `$` becomes cpfg's
// `@v`, the color step `'` becomes `;`, `@O`'s radius becomes cpfg's diameter); the stored
// folder must hold exactly that (run the test with SPRIG_UPDATE_VLAB=1 to write them
// after changing a grammar), and, read back as cpfg reads it, must give the same module
// string (up to those renamings) and the same skeleton as the native grammar. Sprig's
// predefined leaf `~l` becomes cpfg's surface `l`: a `leaf.s` beside the grammar, which the
// view file names.

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "lsystem/view_file.h"
#include "tests/scratch_dir.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

struct CpfgObject {
  std::string grammar;  ///< NAME.l
  std::string view;     ///< NAME.v (empty: no view file)
  std::string leaf;     ///< leaf.s (empty: none), the surface of Sprig's predefined leaf `~l`
};

/// Sprig's predefined leaf `~l` as a cpfg surface file: one Bezier patch, an ovate blade of
/// length 1 along the heading and at most 0.38 wide on either side (as organisms/
/// tree_builder.cpp's blade), facing the turtle's up (the file's UP is cpfg's, -U in Sprig).
const char* const kLeafSurface =
    "-0.55 0.55  0 1  0 0\n"
    "PRECISION S: 6 T: 4\n"
    "CONTACT POINT  X: 0 Y: 0 Z: 0\n"
    "END POINT  X: 0 Y: 1 Z: 0\n"
    "HEADING  X: 0 Y: 1 Z: 0\n"
    "UP  X: 0 Y: 0 Z: -1\n"
    "SIZE: 1\n"
    "blade\n"
    "TOP COLOR: 0 DIFFUSE: 0.00 BOTTOM COLOR: 0 DIFFUSE: 0.00\n"
    "AL: ~ A: ~ AR: ~\n"
    "L: ~ R: ~\n"
    "BL: ~ B: ~ BR: ~\n"
    "-0.03 0 0  -0.01 0 0  0.01 0 0  0.03 0 0\n"
    "-0.55 0.3 0  -0.18 0.3 0  0.18 0.3 0  0.55 0.3 0\n"
    "-0.45 0.75 0  -0.15 0.75 0  0.15 0.75 0  0.45 0.75 0\n"
    "-0.01 1 0  -0.003 1 0  0.003 1 0  0.01 1 0\n";

/// The argument of every `@O(...)` from column `from` on, wrapped as `2*(...)` (radius to diameter).
std::string doubleSpheres(std::string s, size_t from) {
  for (size_t i = s.find("@O(", from); i != std::string::npos; i = s.find("@O(", i + 3)) {
    size_t b = i + 3;
    int depth = 0;
    size_t e = b;
    for (; e < s.size(); ++e) {
      if (s[e] == '(') ++depth;
      if (s[e] == ')' && depth-- == 0) break;
    }
    s = s.substr(0, b) + "2*(" + s.substr(b, e - b) + ")" + s.substr(e);
  }
  return s;
}

/// grammars/NAME.lsys in cpfg's notation.
CpfgObject toCpfg(const std::string& lsys) {
  CpfgObject out;
  std::istringstream in(lsys);
  std::string line;
  static const std::regex angle(R"(^\s*angle:\s*(\S+)\s*$)");
  // A predecessor `@O(r)`: cpfg's parameter is the diameter; the radius is read back in a
  // statement block, so the condition and successor see what they saw.
  static const std::regex spherePred(R"(^(\s*)@O\((\w+)\)\s*:\s*(.*?)-->(.*)$)");
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_match(line, m, angle)) {
      out.view += "angle increment: " + m[1].str() + "\n";
      out.grammar += "\n";  // keep line numbers
      continue;
    }
    for (size_t i = line.find('$'); i != std::string::npos; i = line.find('$', i + 2)) line.replace(i, 1, "@v");
    for (char& c : line)
      if (c == '\'') c = ';';
    if (std::regex_match(line, m, spherePred)) {
      line = m[1].str() + "@O(" + m[2].str() + "_d) : { " + m[2].str() + " = " + m[2].str() + "_d / 2; } " + m[3].str() +
             "-->" + doubleSpheres(m[4].str(), 0);
    } else if (size_t arrow = line.find("-->"); arrow != std::string::npos) {
      line = doubleSpheres(line, arrow);
    } else if (size_t ax = line.find("axiom:"); ax != std::string::npos) {
      line = doubleSpheres(line, ax);
    }
    out.grammar += line + "\n";
  }
  // Sprig's predefined leaf `~l` is a surface file in cpfg, named by the view file.
  if (lsys.find("~l") != std::string::npos) {
    out.view += "surface: l leaf.s 1 6 4\n";
    out.leaf = kLeafSurface;
  }
  return out;
}

std::string cpfgName(const std::string& name) {
  if (name == "$") return "@v";
  if (name == "'") return ";";
  return name;
}

}  // namespace

TEST_CASE("every shipped grammar runs as a cpfg .l file in a vlab object folder", "[lsystem][cpfg]") {
  const std::filesystem::path grammars = std::filesystem::path(SPRIG_SOURCE_DIR) / "grammars";
  const bool update = std::getenv("SPRIG_UPDATE_VLAB") != nullptr;
  size_t converted = 0, stored = 0;
  for (const auto& entry : std::filesystem::directory_iterator(grammars)) {
    if (entry.path().extension() != ".lsys") continue;
    const std::string name = entry.path().stem().string();
    INFO(name);
    const CpfgObject obj = toCpfg(readFile(entry.path()));
    const std::filesystem::path folder = grammars / "vlab" / name;
    const std::string lPath = (folder / (name + ".l")).string();
    const std::filesystem::path vPath = folder / (name + ".v");
    if (update) {
      std::filesystem::create_directories(folder);
      writeFileAtomic(lPath, obj.grammar);
      if (!obj.view.empty()) writeFileAtomic(vPath.string(), obj.view);
      else std::filesystem::remove(vPath);
      if (!obj.leaf.empty()) writeFileAtomic((folder / "leaf.s").string(), obj.leaf);
      else std::filesystem::remove(folder / "leaf.s");
    }
    // The stored object is the conversion of the shipped grammar, byte for byte.
    REQUIRE(std::filesystem::exists(lPath));
    CHECK(readFile(lPath) == obj.grammar);
    CHECK(std::filesystem::exists(vPath) == !obj.view.empty());
    if (!obj.view.empty() && std::filesystem::exists(vPath)) CHECK(readFile(vPath.string()) == obj.view);
    CHECK(std::filesystem::exists(folder / "leaf.s") == !obj.leaf.empty());
    if (!obj.leaf.empty() && std::filesystem::exists(folder / "leaf.s")) CHECK(readFile((folder / "leaf.s").string()) == obj.leaf);
    ++stored;
    ViewFile view;
    if (!obj.view.empty()) view = loadViewFile((folder / (name + ".v")).string());
    GrammarOverrides overrides;
    for (const CpfgSurfaceEntry& sf : view.surfaces) overrides.cpfgSurfaceIds += sf.id;
    const Grammar native = loadGrammar(entry.path().string());
    const Grammar cpfg = loadGrammar(lPath, overrides);
    REQUIRE(cpfg.cpfgNotation());
    Deriver dn(native), dc(cpfg);
    const ModuleString& sn = dn.derive();
    const ModuleString& sc = dc.derive();
    // A grammar that draws random numbers draws Sprig's sequence natively and cpfg's in
    // its .l (docs/GRAMMAR.md, Stochastic productions): its .l derives the string the real
    // cpfg derives from it (tests/assets/cpfg/parity/shipped_NAME/cpfg.str).
    const std::filesystem::path cpfgStr =
        std::filesystem::path(SPRIG_SOURCE_DIR) / "tests/assets/cpfg/parity" / ("shipped_" + name) / "cpfg.str";
    if (std::filesystem::exists(cpfgStr)) {
      std::string text;
      for (char c : readFile(cpfgStr.string()))
        if (c != '\n' && c != '\r') text += c;
      SymbolTable table = dc.symbols();
      const ModuleString want = parseModuleString(text, table);
      REQUIRE(sc.size() == want.size());
      for (size_t i = 0; i < sc.size(); ++i) {
        REQUIRE(dc.symbols().name(sc.symbols[i]) == table.name(want.symbols[i]));
        REQUIRE(sc.paramCount(i) == want.paramCount(i));
        for (uint32_t p = 0; p < sc.paramCount(i); ++p)
          REQUIRE(std::fabs(sc.paramsOf(i)[p] - want.paramsOf(i)[p]) <= 1e-5 * std::max(1.0, std::fabs(want.paramsOf(i)[p])));
      }
      ++converted;
      continue;
    }
    REQUIRE(sn.size() == sc.size());
    REQUIRE(sn.size() > 1);
    for (size_t i = 0; i < sn.size(); ++i) {
      const std::string& a = dn.symbols().name(sn.symbols[i]);
      REQUIRE(cpfgName(a) == dc.symbols().name(sc.symbols[i]));
      REQUIRE(sn.paramCount(i) == sc.paramCount(i));
      const double k = a == "@O" ? 2.0 : 1.0;
      // A .l file's parameters are 32-bit floats, as cpfg's (docs/GRAMMAR.md, Expressions).
      for (uint32_t p = 0; p < sn.paramCount(i); ++p) REQUIRE(sc.paramsOf(i)[p] == Approx(k * sn.paramsOf(i)[p]).epsilon(1e-5));
    }
    // The skeletons: native with the grammar's angle (45 without one), cpfg with the view file.
    // No tropism on either side: a species' tropism (ABOP's bend after each F, which
    // `@Ts(e)` of conifer switches on) and a view file's `tropism:` (cpfg's bend before
    // each move, twist-free frames) are the two notations' own rules (docs/GRAMMAR.md).
    TurtleSettings tn;
    tn.angleDeg = native.angleDeg().value_or(kCpfgDefaultAngleDeg);
    tn.tropism = DVec3(0);
    const Skeleton kn = Turtle(dn.symbols(), tn).run(dn.interpret(sn));
    const Skeleton kc = Turtle(dc.symbols(), cpfgTurtleSettings(obj.view.empty() ? nullptr : &view, {})).run(dc.interpret(sc));
    REQUIRE(kn.internodes.size() == kc.internodes.size());
    // Positions within float rounding of the .l file's parameters.
    auto near = [](const DVec3& a, const DVec3& b) { return glm::length(a - b) < 1e-5 * (1 + glm::length(a)); };
    for (size_t i = 0; i < kn.internodes.size(); ++i) {
      REQUIRE(near(kn.internodes[i].start, kc.internodes[i].start));
      REQUIRE(near(kn.internodes[i].end, kc.internodes[i].end));
      REQUIRE(kn.internodes[i].parent == kc.internodes[i].parent);
    }
    REQUIRE(kn.organs.size() == kc.organs.size());
    for (size_t i = 0; i < kn.organs.size(); ++i) {
      REQUIRE(near(kn.organs[i].position, kc.organs[i].position));
      REQUIRE(kn.organs[i].radius == Approx(kc.organs[i].radius));
      // `~l`: the leaf surface's mesh, its base at the turtle and its tip a leaf length
      // (the radius) along the heading.
      REQUIRE(kc.organs[i].triangles.empty() == (kn.organs[i].kind != Organ::Kind::Surface));
      if (kc.organs[i].triangles.empty()) continue;
      const Organ& o = kc.organs[i];
      REQUIRE(o.points.size() == 7 * 5);
      REQUIRE(glm::length(o.points[2] - o.position) < 1e-6);                              // s = 0, t = 1/2
      REQUIRE(glm::length(o.points[32] - (o.position + o.radius * o.heading)) < 1e-6);  // s = 1, t = 1/2
    }
    ++converted;
  }
  CHECK(converted == 16);
  CHECK(stored == 16);
}
