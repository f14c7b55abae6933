// cpfg compatibility: the objects under tests/assets/cpfg/, each with the counts and
// positions cpfg's semantics give (derived by hand in the comments), and the constructs
// Sprig does not implement, each an error naming it at its position.

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/rng.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "lsystem/view_file.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

std::string cpfgAsset(const std::string& name) { return std::string(SPRIG_SOURCE_DIR) + "/tests/assets/cpfg/" + name; }

/// A cpfg object of tests/assets/cpfg (its `plant.l`, and `plant.v` when withView) derived
/// its own number of steps and drawn by the turtle with the view file's settings.
struct Drawn {
  std::string string;  ///< the derived string, in grammar notation
  Skeleton skeleton;
  TurtleState end;
};

Drawn drawObject(const std::string& folder, bool withView) {
  ViewFile view;
  GrammarOverrides o;
  if (withView) {
    view = loadViewFile(cpfgAsset(folder + "/plant.v"));
    for (const CpfgSurfaceEntry& e : view.surfaces) o.cpfgSurfaceIds += e.id;
  }
  Grammar g = loadGrammar(cpfgAsset(folder + "/plant.l"), o);
  REQUIRE(g.cpfgNotation());
  Deriver d(g);
  const ModuleString& s = d.derive();
  Drawn out;
  out.string = formatModuleString(s, d.symbols());
  Turtle t(d.symbols(), cpfgTurtleSettings(withView ? &view : nullptr, TurtleSettings{}));
  out.skeleton = t.run(d.interpret(s));
  out.end = t.endState();
  return out;
}

/// a is b within the float rounding of a .l file's parameters (cpfg's 32-bit floats).
void checkNear(const DVec3& a, const DVec3& b) {
  INFO("got (" << a.x << ", " << a.y << ", " << a.z << "), expected (" << b.x << ", " << b.y << ", " << b.z << ")");
  CHECK(glm::length(a - b) < 1e-6 * (1 + glm::length(b)));
}

/// The skeleton's internodes run from want[k].first to want[k].second, in order.
void checkSegments(const Skeleton& skeleton, const std::vector<std::pair<DVec3, DVec3>>& want) {
  REQUIRE(skeleton.internodes.size() == want.size());
  for (size_t k = 0; k < want.size(); ++k) {
    INFO("internode " << k);
    checkNear(skeleton.internodes[k].start, want[k].first);
    checkNear(skeleton.internodes[k].end, want[k].second);
  }
}

/// The first diagnostic run() throws as an InputError, as "file:line:col: message" when
/// withFile, else "line:col: message"; "no error" when it throws none.
template <class F>
std::string firstError(F&& run, bool withFile) {
  try {
    run();
  } catch (const InputError& e) {
    const Diagnostic& d = e.diagnostics().front();
    const std::string at = std::to_string(d.loc.line) + ":" + std::to_string(d.loc.col) + ": " + d.message;
    return withFile ? d.loc.file + ":" + at : at;
  }
  return "no error";
}

/// The first error message of parsing text as a cpfg grammar `t.l` (or `t.lsys`).
std::string errorOf(const std::string& text, const std::string& file = "t.l") {
  return firstError([&] { parseGrammar(text, file); }, true);
}

std::string viewErrorOf(const std::string& text) {
  return firstError([&] { parseViewFile(text, "t.v"); }, true);
}

}  // namespace

TEST_CASE("cpfg objects: angle increments, continued lines and expressions", "[lsystem][cpfg]") {
  const double s30 = 0.5, c30 = std::sqrt(3.0) / 2, r2 = std::sqrt(0.5);

  SECTION("angle increment from the view file; Lsystem:, Axiom:, a bare homomorphism, Endlsystem") {
    // A --> I+I, I --> F in the homomorphism: F+F turned by 30 degrees.
    Drawn o = drawObject("angle_increment", true);
    CHECK(o.string == "I+I");
    REQUIRE(o.skeleton.internodes.size() == 2);
    checkNear(o.skeleton.internodes[1].end, DVec3(-s30, 1 + c30, 0));
  }

  SECTION("angle factor 8 is 45 degrees; 'initial line width: 0.2 shaded' is a world width") {
    Drawn o = drawObject("angle_factor", true);
    REQUIRE(o.skeleton.internodes.size() == 2);
    checkNear(o.skeleton.internodes[1].end, DVec3(r2, 1 + r2, 0));  // `-` turns right
    CHECK(o.skeleton.internodes[0].baseRadius == Approx(0.1));
  }

  SECTION("without a view file, cpfg's default angle increment of 45 degrees") {
    Drawn o = drawObject("no_view", false);
    REQUIRE(o.skeleton.internodes.size() == 2);
    checkNear(o.skeleton.internodes[1].end, DVec3(-r2, 1 + r2, 0));
    CHECK(cpfgDefaultsUsed(nullptr).find("angle increment 45") == 0);
  }

  SECTION("a production continued on lines that start with a tab") {
    Drawn o = drawObject("continuation", false);
    CHECK(o.string == "F[+(90)F]F");
    REQUIRE(o.skeleton.internodes.size() == 3);
    checkNear(o.skeleton.internodes[1].end, DVec3(-1, 1, 0));
    checkNear(o.skeleton.internodes[2].end, DVec3(0, 2, 0));
  }

  SECTION("expressions: c ? a : b, fabs, trunc rounds, %, <>, ^ below unary minus and left-associative") {
    Drawn o = drawObject("expressions", false);
    CHECK(o.string == "B(10,20)C(2,3,-2,1)D(4,64,0)");
  }
}

TEST_CASE("cpfg objects: widths, colors, the turtle scale, tropism, moves and headings", "[lsystem][cpfg]") {
  const double r2 = std::sqrt(0.5);

  SECTION("widths, colors and the turtle scale: ! # ; , @D") {
    // View: width 4 in world units, increment 1, color 5, increment 2.
    Drawn o = drawObject("width_color", true);
    REQUIRE(o.skeleton.internodes.size() == 6);
    const double radii[] = {2, 1.5, 2, 5, 5, 3};  // 4, 4-1, 3+1, 10, @D(2): 10, !(3) = 3*2
    for (int k = 0; k < 6; ++k) CHECK(o.skeleton.internodes[k].baseRadius == Approx(radii[k]));
    checkNear(o.end.frame.position, DVec3(0, 8, 0));  // four unit steps, then two of length 2
    REQUIRE(o.skeleton.organs.size() == 2);
    CHECK(o.skeleton.organs[0].color == 7);  // 5 + 2
    CHECK(o.skeleton.organs[1].color == 3);  // 7 - 2 - 2
    CHECK(o.skeleton.organs[0].radius == Approx(5));  // @O without a size: the line width is its diameter
  }

  SECTION("tropism from the view file, bent before each move; @Ts(n, e) sets tropism n's elasticity") {
    // T = (0,-1,0) (unit length), e = 0.2. After +(90) H = (-1,0,0): the first F turns H by
    // min(|H x 0.2T|, 1) = 0.2 rad toward T. @Ts(1,0) stops the bending; the branch sets 0.2
    // again: H x 0.2T has length 0.2 cos(0.2), so it turns by that much more.
    Drawn o = drawObject("tropism", true);
    REQUIRE(o.skeleton.internodes.size() == 4);
    const DVec3 e1(-std::cos(0.2), -std::sin(0.2), 0);
    checkNear(o.skeleton.internodes[0].end, e1);
    checkNear(o.skeleton.internodes[1].end, 2.0 * e1);
    const double a = 0.2 + 0.2 * std::cos(0.2);
    checkNear(o.skeleton.internodes[2].end, 2.0 * e1 + DVec3(-std::cos(a), -std::sin(a), 0));
    checkNear(o.skeleton.internodes[3].end, 3.0 * e1);  // `]` restored elasticity 0
  }

  SECTION("@M moves, @R sets the heading (and cpfg's up), @v rolls L horizontal; a bare decomposition") {
    Drawn o = drawObject("move_heading", false);
    CHECK(o.string == "F@M(3,0,1)F@R(1,0,0)F@R(0,0,1,0,1,0)F&(45)@v F");  // a space keeps @v and F apart
    REQUIRE(o.skeleton.internodes.size() == 5);
    checkNear(o.skeleton.internodes[0].end, DVec3(0, 1, 0));
    checkNear(o.skeleton.internodes[1].start, DVec3(3, 0, 1));  // @M: no segment drawn to it
    CHECK(o.skeleton.internodes[1].parent == -1);
    checkNear(o.skeleton.internodes[2].end, DVec3(4, 1, 1));    // @R(1,0,0): heading +X
    checkNear(o.skeleton.internodes[3].end, DVec3(4, 1, 2));    // @R(0,0,1, 0,1,0): heading +Z
    // &(45) after H = +Z, U = -(cpfg's up) = -Y: H = (0, s, c); @v: L = Y x H normalized = +X.
    checkNear(o.skeleton.internodes[4].end, DVec3(4, 1 + r2, 2 + r2));
    checkNear(o.end.frame.left, DVec3(1, 0, 0));
    checkNear(o.end.frame.up, DVec3(0, r2, -r2));
  }
}

TEST_CASE("cpfg objects: elasticity steps, cpfg's old tropism and torque", "[lsystem][cpfg]") {
  SECTION("@Ti without a value adds the tropism's step S, @Td(n, d) subtracts d, @Ts of a missing tropism is ignored") {
    // E 0.1 + S 0.2 = 0.3: the first F turns 0.3 rad down; 0.3 - 0.3 = 0: the others go straight.
    Drawn o = drawObject("elasticity_steps", true);
    REQUIRE(o.skeleton.internodes.size() == 3);
    const DVec3 h(-std::cos(0.3), -std::sin(0.3), 0);
    checkNear(o.skeleton.internodes[0].end, h);
    checkNear(o.skeleton.internodes[1].end, 2.0 * h);
    checkNear(o.skeleton.internodes[2].end, 3.0 * h);
  }

  SECTION("cpfg's old tropism: '_', tropism direction, elasticity increment; the bend follows the move") {
    // After +(90): H = -X, L = -Y, cpfg's up = -Z. `_`: e = 0 + 0.5. F moves to (-1,0,0), then
    // bends: e T.up = 0, e T.L = 0.5: H = cos(30) H + 0.5 L. `_(0)` stops it.
    Drawn o = drawObject("old_tropism", true);
    REQUIRE(o.skeleton.internodes.size() == 2);
    checkNear(o.skeleton.internodes[0].end, DVec3(-1, 0, 0));
    checkNear(o.skeleton.internodes[1].end, DVec3(-1 - std::sqrt(0.75), -0.5, 0));
  }

  SECTION("torque: U turns about H by cpfg's quaternion rule, H stays") {
    // D = 0.5 X projected perpendicular to H = +Y: (0.5, 0, 0). cpfg's up (0,0,-1) turns by
    // |up x D| = 0.5 rad about +Y (cpfg's q^-1 v q with the axis up x D = -Y): Sprig's
    // U = -(cpfg's up) = (sin 0.5, 0, cos 0.5).
    Drawn o = drawObject("torque", true);
    REQUIRE(o.skeleton.internodes.size() == 1);
    checkNear(o.end.frame.position, DVec3(0, 1, 0));
    checkNear(o.end.frame.heading, DVec3(0, 1, 0));
    checkNear(o.end.frame.up, DVec3(std::sin(0.5), 0, std::cos(0.5)));
    checkNear(o.end.frame.left, DVec3(-std::cos(0.5), 0, std::sin(0.5)));
  }
}

TEST_CASE("cpfg objects: bran and biran; spheres and discs", "[lsystem][cpfg]") {
  SECTION("bran and biran draw from the seeded generator") {
    Drawn a = drawObject("random", false), b = drawObject("random", false);
    CHECK(a.string == b.string);
    Grammar g = loadGrammar(cpfgAsset("random/plant.l"));
    Deriver d(g);
    const ModuleString& s = d.derive();
    REQUIRE(s.size() == 1);
    REQUIRE(s.paramCount(0) == 5);
    const double* p = s.params.data() + s.offsets[0];
    CHECK(p[0] == 10);  // every trial below p = 1
    CHECK(p[1] == 0);
    CHECK(p[2] == std::floor(p[2]));
    CHECK((p[2] >= 0 && p[2] <= 20));
    CHECK((p[3] > 0 && p[3] < 1));
    CHECK((p[4] > 0 && p[4] < 1));
  }

  SECTION("@O(d) and @o(d) spheres of diameter d, @c(d) a disc in the HL plane") {
    Drawn o = drawObject("spheres_discs", true);
    REQUIRE(o.skeleton.organs.size() == 3);
    CHECK(o.skeleton.organs[0].kind == Organ::Kind::Sphere);
    CHECK(o.skeleton.organs[0].radius == Approx(1));
    CHECK(o.skeleton.organs[1].kind == Organ::Kind::Sphere);
    CHECK(o.skeleton.organs[1].radius == Approx(2));
    checkNear(o.skeleton.organs[1].position, DVec3(0, 1, 0));
    const Organ& disc = o.skeleton.organs[2];
    CHECK(disc.kind == Organ::Kind::Polygon);
    REQUIRE(disc.points.size() == 32);
    checkNear(disc.points[0], DVec3(0, 3, 0));   // center (0,2,0) + H
    checkNear(disc.points[8], DVec3(-1, 2, 0));  // center + L
  }
}

TEST_CASE("cpfg view file", "[lsystem][cpfg]") {
  SECTION("turtle keys") {
    ViewFile v = parseViewFile("angle factor: 12\ninitial line width: 3 pixels\nline width increment: 0.5\n"
                               "initial color: 2 4\ncolor increment: 3\ninitial scale: 2\nscale multiplier: 1.5\n"
                               "tropism: T: 0 0 3 A: 90 I: 0.5 E: 0.1 S: 0.05\n",
                               "t.v");
    CHECK(*v.angleDeg == Approx(30));
    CHECK(*v.lineWidth == 3);
    CHECK(*v.lineStyle == CpfgLineStyle::Pixel);
    CHECK(*v.widthIncrement == 0.5);
    CHECK(*v.initialColor == 2);
    CHECK(*v.colorIncrement == 3);
    CHECK(*v.initialScale == 2);
    CHECK(*v.scaleMultiplier == 1.5);
    REQUIRE(v.tropisms.size() == 1);
    CHECK(v.tropisms[0].direction.z == Approx(0.5));  // unit length times the intensity
    CHECK(v.tropisms[0].angleDeg == 90);
    CHECK(v.tropisms[0].elasticity == 0.1);
    CHECK(v.tropisms[0].step == 0.05);
    CHECK(v.warnings.empty());
  }
  SECTION("viewer keys are warnings") {
    ViewFile v = parseViewFile("/* view */\nviewpoint: 0,0,1\nrender mode: shaded\nz buffer: on\n", "t.v");
    REQUIRE(v.warnings.size() == 1);
    CHECK(v.warnings[0].loc.line == 2);
    CHECK(v.warnings[0].message == "ignored, as they set how cpfg's window shows the model, not its geometry: "
                                   "'viewpoint:', 'render mode:', 'z buffer:'");
  }
  SECTION("line style: as cpfg reads it, a word it does not know keeps the style in effect") {
    ViewFile v = parseViewFile("line style: cylinder\nline style: wireframe\n", "t.v");
    CHECK(*v.lineStyle == CpfgLineStyle::Cylinder);
    REQUIRE(v.warnings.size() == 1);
    CHECK(v.warnings[0].loc.line == 2);
    CHECK(v.warnings[0].message == "'line style: wireframe' is none of cpfg's line styles (pixel, polygon, cylinder): as cpfg "
                                   "does, the line style in effect is kept");
    CHECK(*parseViewFile("line style: 2\n", "t.v").lineStyle == CpfgLineStyle::Polygon);  // cpfg's digits 1 to 3
    CHECK(viewErrorOf("line style: 7\n") == "t.v:1:13: 'line style:' is pixel, polygon or cylinder (or 1, 2, 3), got '7'");
  }
  SECTION("an object given by a relative path starting with './' reads its files") {
    const std::string rel = "./" + std::filesystem::relative(cpfgAsset("function/plant.v")).generic_string();
    ViewFile v = loadViewFile(rel);
    CHECK(v.functions.size() == 3);
  }
  SECTION("errors") {
    CHECK(viewErrorOf("angle increment: 30\nangel factor: 8\n") ==
          "t.v:2:1: unknown view file command 'angel factor:' (did you mean 'angle factor'?)");
    // A missing surface file is skipped, as cpfg skips it; a background scene's errors wait
    // for a drawing (GrowthEngine).
    CHECK(viewErrorOf("line: l leaf.s 1\n") == "no error");
    CHECK(viewErrorOf("line: l leaf.s\n") == "t.v:1:7: expected 'line: X FILE.s size [s-precision t-precision [texture]]'");
    CHECK(viewErrorOf("line: l leaf.s 1 3\n") ==
          "t.v:1:18: a 'line:' takes two precisions (s t) after its size, then an optional texture; cpfg reads a single number there and drops it");
    const ViewFile scene = parseViewFile("background scene: a.dat\n", "t.v");
    REQUIRE(scene.unsupportedDrawing);
    CHECK(scene.unsupportedDrawing->message == "the background scene file 'a.dat': cannot find file");
    CHECK(scene.unsupportedDrawing->loc.col == 19);
    CHECK_FALSE(parseViewFile("angle factor: 8\n", "t.v").unsupportedDrawing);
    CHECK(viewErrorOf("tropism direction: 0,0,0\n") == "t.v:1:20: 'tropism direction:' must not be the zero vector");
    CHECK(viewErrorOf("angle increment: thirty\n") == "t.v:1:18: 'angle increment:' expects 1 number, got 'thirty'");
    CHECK(viewErrorOf("tropism: E: 0.2\n") == "t.v:1:10: a tropism needs a non-zero vector 'T: x y z'");
    CHECK(viewErrorOf("#include \"x.v\"\n") == "t.v:1:1: C preprocessor directive '#include' in a view file is not supported");
  }
}

TEST_CASE("cpfg constructs Sprig does not implement are errors", "[lsystem][cpfg]") {
  SECTION("commands") {
    CHECK(errorOf("axiom: F@Tx(1)\n", "t.lsys") == "t.lsys:1:9: cpfg's '@Tx' (texture) is supported only in cpfg's notation (a .l file), with a view file's 'texture:' lines");
    CHECK(errorOf("axiom: F{(1)F}(1)\n") == "t.l:1:9: cpfg's '{(type)' (generalized cylinder) is not supported");
    CHECK(errorOf("axiom: A\nA --> F$A\n") ==
          "t.l:2:8: cpfg's '$' ends a sub-L-system call '?(n, scale)', and this file makes none (ABOP's roll to vertical is '@v' in cpfg)");
    CHECK(errorOf("axiom: F~l\n") == "no error");  // draws nothing, as in cpfg (a warning: cpfg surface files)
    CHECK(errorOf("axiom: ?P(0,0)A\n") == "no error");
    CHECK(errorOf("axiom: ?E(1)?E(1,2)\n?E(t,la) --> *\n") == "no error");  // vlab's clover: cpfg accepts it
    CHECK(errorOf("axiom: A\nhomomorphism\nA --> F?U(0,0,0)\n") ==
          "t.l:3:8: cpfg's query module '?U' in an interpretation rule is not supported (its values would be lost with "
          "the interpreted string)");
    CHECK(errorOf("axiom: A\nA --> ?(2,1)B$\n") ==
          "t.l:2:7: '?(2, ...)' calls a sub-L-system the file does not define (no 'lsystem: 2' after an 'endlsystem')");
    CHECK(errorOf("axiom: F@bo(1)\n") == "t.l:1:9: cpfg's '@bo' (circle boundary) is not supported");
    CHECK(errorOf("axiom: F@Q\n") == "t.l:1:9: unknown cpfg command '@Q'");
  }
  SECTION("statements, blocks, preprocessor, several L-systems") {
    CHECK(errorOf("axiom: A(1)\nA(y) : { x = y / 2; x < 10 --> B(x)\n") == "t.l:2:8: unclosed '{' of a statement block");
    CHECK(errorOf("#if 1\naxiom: A\n#endif\n") == "no error");
    CHECK(errorOf("#if 1 +\naxiom: A\n#endif\n") ==
          "t.l:1:4: cannot evaluate '#if 1 +' (expected a constant expression of numbers and #define names)");
    CHECK(errorOf("#elif 1\naxiom: A\n") ==
          "t.l:1:1: cpfg's C preprocessor directive '#elif' is not supported (Sprig's preprocessor reads #define, "
          "#undef, #include, #ifdef, #ifndef, #else and #endif)");
    CHECK(errorOf("#define K (1 > 0 ? 2 : 3)\naxiom: A\n") == "no error");
    CHECK(errorOf("lsystem: 1\naxiom: A\nendlsystem\n", "t.l") == "no error");
    CHECK(errorOf("lsystem: 1\naxiom: A\nlsystem: 2\naxiom: B\n") ==
          "t.l:3:1: several L-systems in one file (cpfg's sub-L-systems) are not supported (the first is at line 1)");
    CHECK(errorOf("ring lsystem\naxiom: A\n") == "no error");  // cpfg_parity_test.cpp: ring
    CHECK(errorOf("axiom: A(1)\nA(x) --> A(srand(2))\n").find(
              "t.l:2:12: cpfg's function 'srand' is supported only as a statement ('srand(s);') of a 'Start:'") == 0);
    CHECK(errorOf("axiom: A(1)\nA(x) --> A(func(1, x))\n") ==
          "t.l:2:12: cpfg's func(n, x) reads the view file's function files, and it names none ('function: NAME.func')");
  }
  SECTION("printf: a statement with numeric conversions") {
    CHECK(errorOf("axiom: A(1)\nA(x) : { printf(\"%s\", x); } 1 --> A(x)\n") ==
          "t.l:2:17: printf's conversion '%s' is not supported (only numbers: %d %i %o %u %x %c %f %e %g %a)");
    CHECK(errorOf("axiom: A(1)\nA(x) : { printf(\"%g %g\", x); } 1 --> A(x)\n") ==
          "t.l:2:10: printf's format has 2 conversion(s) for 1 value(s)");
    CHECK(errorOf("axiom: A(1)\nA(x) --> A(printf(\"%g\", x))\n") ==
          "t.l:2:12: cpfg's function 'printf' (output; it is a statement of its own) is not supported");
    CHECK(errorOf("axiom: A(1)\nA(x) : { printf(x); } 1 --> A(x)\n") ==
          "t.l:2:17: printf's first argument must be a format in double quotes");
    CHECK(errorOf("Start: { printf(\"%5.2f%%\\n\", 2); }\naxiom: A\n") == "no error");
  }
  SECTION("an error in a continued line is reported at its own line") {
    CHECK(errorOf("axiom: A\nA --> F\n\tF@bo(2)\n") == "t.l:3:3: cpfg's '@bo' (circle boundary) is not supported");
  }
}

TEST_CASE("cpfg notation in Sprig's .lsys files", "[lsystem][cpfg]") {
  SECTION("@Ts(n, e) sets the elasticity of tropism n (Sprig's one tropism is number 1)") {
    Grammar g = parseGrammar("axiom: @Ts(1, 0.5)F@Ts(2, 0.9)F\n", "t.lsys");
    TurtleSettings s;
    Turtle t(g.symbols(), s);
    t.run(g.axiom());
    CHECK(t.endState().elasticity == 0.5);  // tropism 2 does not exist: ignored, as cpfg does
  }
  SECTION("`,` and `;` are modules; bare keywords; Endlsystem") {
    Grammar g = parseGrammar("axiom: F;F,F\nhomomorphism\nF --> G\nEndlsystem\n", "t.lsys");
    CHECK(g.axiom().size() == 5);
    CHECK(g.hasInterpretation());
  }
  SECTION("a bare turn is noted; ^ keeps Sprig's precedence") {
    CHECK(parseGrammar("axiom: F+F\n", "t.lsys").usesDefaultAngle());
    CHECK(!parseGrammar("axiom: F+(30)F\n", "t.lsys").usesDefaultAngle());
    Grammar g = parseGrammar("axiom: A(-2^2, 2^3^2)\n", "t.lsys");
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "A(-4,512)");
  }
}

namespace {

/// The string after `steps` steps of text (a grammar named file).
std::string derived(const std::string& text, int steps, const std::string& file = "t.l") {
  Grammar g = parseGrammar(text, file);
  DeriveOptions opt;
  opt.steps = steps;
  Deriver d(g, opt);
  return formatModuleString(d.derive(), d.symbols());
}

}  // namespace

TEST_CASE("cpfg statements in productions", "[lsystem][cpfg]") {
  SECTION("assignments before the condition: locals the condition and the successor read") {
    const std::string g = "axiom: A(4)A(8)\nA(y) : { x = y / 2; s = x * x; } s < 10 --> B(x)\n";
    CHECK(derived(g, 1) == "B(2)A(8)");  // 4: x 2, s 4; 8: s 16, no match
  }
  SECTION("if and else after the condition; a formal parameter may be assigned") {
    const std::string g = "axiom: A(20)A(3)\nA(y) : * { if (y > 10) { y = 10; } else { y = y + 1; } } --> B(y)\n";
    CHECK(derived(g, 1) == "B(10)B(4)");
  }
  SECTION("while and do ... while") {
    CHECK(derived("axiom: A(4)\nA(n) : { k = 0; s = 0; while (k < n) { k = k + 1; s = s + k; } } * --> S(s)\n", 1) == "S(10)");
    CHECK(derived("axiom: A(5)A(0)\nA(n) : { k = 0; do { k = k + 2; } while (k < n); } * --> D(k)\n", 1) == "D(6)D(2)");
  }
  SECTION("locals start at 0 in every application") {
    CHECK(derived("axiom: A(1)\nA(n) : { if (n > 5) { t = 7; } } * --> A(n + 5)T(t)\n", 2) == "A(11)T(7)T(0)");
  }
  SECTION("a block over several lines (cpfg notation)") {
    CHECK(derived("axiom: A(2)\nA(y) : {\n\tx = y * 3;\n} x > 5 --> B(x)\n", 1) == "B(6)");
    // cpfg's reader goes on inside the open braces without tabs, across blank lines and
    // comments, up to the arrow (vlab's Ridley, spiral.l:14).
    CHECK(derived("axiom: A(2)\nA(y) : y > 1 {  // a comment\n  x = y * 3;\n\n    while (x < 10) {\n x = x + 2;\n }\n} --> B(x)\nB(x) --> C(x)\n", 2) ==
          "C(10)");  // 6, 8, 10
    // `AXIOM : cond --> succ` is a production of the modules A X I O M (vlab's Lilac), not an axiom.
    CHECK(derived("Axiom: AXIOM\nAXIOM : 1 --> F(2)\n", 1) == "F(2)");
  }
  SECTION("stochastic productions run their own statements") {
    const std::string g = "seed: 3\naxiom: A(1)A(1)A(1)A(1)\nA(y) : { x = 10; } * --> X(x) : 1\nA(y) : { z = 20; } * --> Z(z) : 1\n";
    const std::string out = derived(g, 1);
    for (size_t k = 0; k < out.size(); ++k)
      if (out[k] == 'X') CHECK(out.compare(k, 5, "X(10)") == 0);
      else if (out[k] == 'Z') CHECK(out.compare(k, 5, "Z(20)") == 0);
  }
  SECTION("errors") {
    CHECK(errorOf("axiom: A(1)\nA(y) : { x = y } * --> B(x)\n") ==
          "t.l:2:10: missing ';' after the assignment to 'x' (cpfg requires one after every statement)");
    CHECK(errorOf("axiom: A(1)\nA(y) : { if (y > 1) x = 2; } * --> B(y)\n") ==
          "t.l:2:21: expected '{' after 'if (...)' (cpfg requires braces)");
    CHECK(errorOf("axiom: A(1)\nA(y) : { x += 1; } * --> B(y)\n") ==
          "t.l:2:12: expected '=' after 'x' (statements are assignments, 'if', 'while' and 'do')");
    CHECK(errorOf("#define K 2\naxiom: A(1)\nA(y) : { K = 1; } * --> B(y)\n") == "t.l:3:10: cannot assign to 'K': it is a #define");
    CHECK(errorOf("Start: { srand(3); }\naxiom: A\n") == "no error");
    CHECK(derived("axiom: A(2)\nA(y) : { x = 1; fabs(y); x = x + 1; } * --> B(x)\n", 1) == "B(2)");  // a call alone: value dropped
    CHECK(derived("axiom: A(2)\nA(y) : { x = y; x - x / 2; } * --> B(x)\n", 1) == "B(2)");  // an expression alone: dropped
    try {
      derived("axiom: A(1)\nA(y) : { while (1) { y = y; } } * --> B(y)\n", 1);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().message == "the statements of production 'A(y)' loop more than 10000000 times at step 1");
    }
  }
}

TEST_CASE("cpfg consider: with brackets; maximum depth beyond 256", "[lsystem][cpfg]") {
  SECTION("consider: listing [ and ] follows brackets; without them a right context passes over them") {
    CHECK(derived("consider: BA[]\naxiom: A[C]B\nA > B --> X\n", 1) == "X[C]B");
    // A's right context: the branch [B] is skipped, C is not considered, the string ends.
    CHECK(derived("consider: BA[]\naxiom: A[B]C\nA > B --> X\n", 1) == "A[B]C");
    // Without them cpfg ignores '[' and finds B inside the branch (RconDiff).
    CHECK(derived("consider: BA\naxiom: A[B]C\nA > B --> X\n", 1) == "X[B]C");
    // Sprig's notation always follows brackets.
    Grammar g = parseGrammar("consider: BA\naxiom: A[B]C\nA > B --> X\n", "t.lsys");
    Deriver d(g, DeriveOptions{.steps = 1});
    CHECK(formatModuleString(d.derive(), d.symbols()) == "A[B]C");
  }
  SECTION("decomposition 5000 levels deep (vlab's Ridley needs 3000)") {
    // B(n) --> F B(n - 1) nests one level per F: B(5000) ends as 5000 F and B(0), which no
    // rule matches, at depth 5000 <= maximum depth.
    Grammar g = parseGrammar("axiom: A(5000)\nA(n) --> B(n)\ndecomposition\nmaximum depth: 6000\nB(n) : n > 0 --> F B(n - 1)\n", "t.l");
    Deriver d(g, DeriveOptions{.steps = 1});
    const ModuleString& s = d.derive();
    REQUIRE(s.size() == 5001);
    CHECK(formatModuleString(s, d.symbols()) == std::string(5000, 'F') + "B(0)");
    // maximum depth 4000 stops there: 4000 F and B(1000), not decomposed further.
    Grammar g4 = parseGrammar("axiom: A(5000)\nA(n) --> B(n)\ndecomposition\nmaximum depth: 4000\nB(n) : n > 0 --> F B(n - 1)\n", "t.l");
    Deriver d4(g4, DeriveOptions{.steps = 1});
    CHECK(formatModuleString(d4.derive(), d4.symbols()) == std::string(4000, 'F') + "B(1000)");
  }
  SECTION("decomposition nested deeper than 100000 levels is an error") {
    CHECK(derived("axiom: A\nA --> B\ndecomposition\nmaximum depth: 1000\nB --> CD\n", 1) == "CD");
    // C --> FC nests without end: 1000 levels at maximum depth 1000; past 100000, an error.
    CHECK(derived("axiom: C\ndecomposition\nmaximum depth: 1000\nC --> FC\n", 1) == std::string(1000, 'F') + "C");
    try {
      derived("derivation length: 1\naxiom: A\ndecomposition\nmaximum depth: 1000000\nA --> FA\n", 1);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().loc.line == 5);
      CHECK(e.diagnostics().front().message ==
            "decomposition nested deeper than 100000 levels at step 1 (maximum depth 1000000): not supported");
    }
  }
}

TEST_CASE("cpfg Start, StartEach, EndEach and End blocks over global variables", "[lsystem][cpfg]") {
  SECTION("the axiom reads the global variables the Start: block set (vlab's two-trees and pallaea)") {
    CHECK(derived("Start: { d = 3; }\naxiom: S A(1, d + 1)\n", 0) == "SA(1,4)");
    // Each derivation starts again from the Start: block.
    CHECK(derived("Start: { d = 3; }\nEndEach: { d = d + 1; }\naxiom: A(d)\nA(x) --> A(x + d)\n", 2) == "A(10)");
    // Sprig's notation reads the axiom before any block runs: an error there.
    CHECK(errorOf("Start: { d = 3; }\naxiom: S A(1, d + 1)\n", "t.lsys") ==
          "t.lsys:2:15: cpfg's global variable 'd' in the axiom is not supported (Sprig reads the axiom before the "
          "'Start:' block assigns it): write its value");
  }
  SECTION("a counter the conditions read") {
    // i is 0 at step 1, 1 at step 2, ...: A grows F while i < 3.
    const std::string g =
        "derivation length: 5\nStart: { i = 0; }\nEndEach: { i = i + 1; }\naxiom: A\nA : i < 3 --> FA\nA : i >= 3 --> B\n";
    CHECK(derived(g, 5) == "FFFB");
  }
  SECTION("StartEach runs before each step; locals and globals side by side") {
    const std::string g = "Start: { n = 10; }\nStartEach: { n = n * 2; }\naxiom: A(0)\nA(x) : { y = x + n; } * --> A(y)\n";
    CHECK(derived(g, 2) == "A(60)");  // step 1: n 20, y 20; step 2: n 40, y 60
  }
  SECTION("a production assigns a global: the modules after it see the new value, as in cpfg") {
    // Each A counts itself into n; B copies the count of the A's to its left.
    const std::string g = "Start: { n = 0; }\nStartEach: { n = 0; }\naxiom: A B A B\nA : { n = n + 1; } * --> A\n"
                          "B --> B(n)\nB(x) --> B(n)\n";
    CHECK(derived(g, 1) == "AB(1)AB(2)");
    CHECK(derived(g, 2) == "AB(1)AB(2)");
  }
  SECTION("errors") {
    CHECK(errorOf("Start: { g = 1; }\naxiom: A\nA : * { g = 2; } --> B\n", "t.lsys") ==
          "t.lsys:3:9: cannot assign the global variable 'g' in a production of a .lsys file (Sprig assigns globals only "
          "in 'Start:', 'StartEach:', 'EndEach:' and 'End:' blocks; a .l file's productions may)");
    CHECK(errorOf("Start: { g = 1; }\naxiom: A\nhomomorphism\nA : * { g = 2; } --> B\n") ==
          "t.l:4:9: cannot assign the global variable 'g' in an interpretation rule (cpfg would change it whenever it "
          "draws the string): not supported");
    CHECK(errorOf("Start: i = 0;\naxiom: A\n") == "t.l:1:8: expected '{ statements }' after 'Start:'");
    CHECK(errorOf("Start: { i = 0; }\nStart: { j = 0; }\naxiom: A\n") == "t.l:2:1: duplicate 'start:' (first at line 1)");
  }
}

TEST_CASE("cpfg query modules", "[lsystem][cpfg]") {
  // tests/assets/cpfg/query: values from its reference.py (cpfg's own turtle, independent of
  // Sprig's): with the view file's 30 degrees, three F on each axis, and
  const double c30 = std::sqrt(3.0) / 2;
  const Grammar g = loadGrammar(cpfgAsset("query/plant.l"));
  SECTION("the view file's turtle: apex at (-1.5, 2.598), branch tip 3 below it") {
    const ViewFile view = loadViewFile(cpfgAsset("query/plant.v"));
    DeriveOptions opt;
    opt.queryTurtle = cpfgTurtleSettings(&view, TurtleSettings{});
    Deriver d(g, opt);
    const ModuleString& s = d.derive();
    CHECK(countSymbol(s, d.symbols(), "F") == 6);
    std::vector<double> want = {-1.5, 3 * c30, -1.5, 3 * c30, -3, 0, 0, -1, -c30, -0.5, 0, 0.5, -c30, 0};
    std::vector<double> got;
    for (size_t i = 0; i < s.size(); ++i)
      if (d.symbols().name(s.symbols[i])[0] == '?')
        for (double v : s.paramsOf(i)) got.push_back(v);
    REQUIRE(got.size() == want.size());
    for (size_t k = 0; k < want.size(); ++k) CHECK(got[k] == Approx(want[k]).margin(1e-12));
    // The drawn main axis ends where ?P says.
    Turtle t(d.symbols(), cpfgTurtleSettings(&view, TurtleSettings{}));
    Skeleton sk = t.run(s);
    REQUIRE(sk.internodes.size() == 6);
    checkNear(sk.internodes[2].end, DVec3(-1.5, 3 * c30, 0));
    checkNear(sk.internodes[5].end, DVec3(-1.5, 3 * c30, -3));
  }
  SECTION("without a view file: cpfg's 45 degrees grow the main axis once more") {
    Deriver d(g);
    const ModuleString& s = d.derive();
    CHECK(countSymbol(s, d.symbols(), "F") == 7);
    const double r2 = std::sqrt(0.5);
    CHECK(formatModuleString(s, d.symbols()).substr(0, 12) == "+F(1)F(1)F(1");
    size_t q = 0;
    while (d.symbols().name(s.symbols[q]) != "?P") ++q;
    CHECK(s.paramsOf(q)[0] == Approx(-4 * r2));
    CHECK(s.paramsOf(q)[1] == Approx(4 * r2));
  }
  SECTION("the axiom's queries are filled before the first step, and through the homomorphism") {
    Grammar h = parseGrammar("derivation length: 0\naxiom: A?P(0,0)B?P(0,0)?P\nhomomorphism\nA --> F(2)\nB --> f(1)\n", "t.l");
    Deriver d(h);
    CHECK(formatModuleString(d.current(), d.symbols()) == "A?P(0,2)B?P(0,3)?P");
  }
}

TEST_CASE("cpfg predecessors of several modules", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/multi_predecessor, derived by hand in its comment") {
    Grammar g = loadGrammar(cpfgAsset("multi_predecessor/plant.l"));
    Deriver d(g);
    CHECK(formatModuleString(d.derive(), d.symbols()) == "D(3)CZCE(5)[B(6)]CG");
  }
  SECTION("left context before the first module; the replaced modules are not rewritten again") {
    // X < A B: only the first A B follows X; B --> Q rewrites the B not consumed.
    Grammar g = parseGrammar("derivation length: 2\naxiom: XABAB\nX < A B --> Y\nB --> Q\nY --> YY\n", "t.l");
    Deriver d(g);
    CHECK(formatModuleString(d.step(), d.symbols()) == "XYAQ");
    CHECK(formatModuleString(d.step(), d.symbols()) == "XYYAQ");
  }
  SECTION("stochastic choice among predecessors of different lengths counts each once") {
    Grammar g = parseGrammar("derivation length: 1\nseed: 3\naxiom: AB\nA B --> X : 1\nA --> Y : 0\n", "t.l");
    CHECK(formatModuleString(derive(g), g.symbols()) == "X");
  }
}

TEST_CASE("cpfg predecessors of several modules in decomposition and homomorphism", "[lsystem][cpfg]") {
  // cpfg (generate.c ApplyRecursiveProductions, interpret.c InterpretHomomorphism): the
  // rule's modules match the modules after the first in the string being decomposed or
  // interpreted (a successor, or at depth 0 the L-system string itself) and are all
  // replaced; a successor's end ends the match.
  auto interpreted = [](const std::string& text) {
    Grammar g = parseGrammar(text, "t.l");
    Deriver d(g);
    return formatModuleString(d.interpret(d.derive()), d.symbols());
  };
  SECTION("decomposition: inside a production's successor") {
    // S --> A B C A D; A B matches at 0 (X), C stays, the second A is followed by D: Y.
    CHECK(derived("axiom: S\nS --> ABCAD\ndecomposition\nA B --> X\nA --> Y\n", 1) == "XCYD");
    CHECK(derived("axiom: S\nS --> A(1)B(2)\ndecomposition\nA(x) B(y) --> C(x + y)\n", 1) == "C(3)");
  }
  SECTION("decomposition: a successor's end ends the match") {
    // S --> A and T --> B are two successors: A is the whole of the first.
    CHECK(derived("axiom: ST\nS --> A\nT --> B\ndecomposition\nA B --> X\n", 1) == "AB");
  }
  SECTION("decomposition: a module no production rewrites matches the string after it, whose modules it consumes") {
    // The axiom, in step 1 (cpfg does not decompose it before): A B --> X(1), C stays.
    CHECK(derived("axiom: ABC\ndecomposition\nA B --> X(1)\n", 0) == "ABC");
    CHECK(derived("axiom: ABC\ndecomposition\nA B --> X(1)\n", 1) == "X(1)C");
    // Step 1: A meets C(1) (the string before rewriting), n = 1: no match; C(1) --> C(2).
    // Step 2: A meets C(2): X, and C(2) is consumed (its production does not apply).
    const std::string g = "axiom: AC(1)\nC(n) --> C(n + 1)\ndecomposition\nA C(n) : n > 1 --> X\n";
    CHECK(derived(g, 1) == "AC(2)");
    CHECK(derived(g, 2) == "X");
  }
  SECTION("decomposition: recursively, up to maximum depth") {
    // S --> A B (depth 1) --> C D (depth 2) --> E D (depth 3).
    const std::string rules = "S --> AB\nA B --> CD\nC --> E\n";
    CHECK(derived("axiom: S\ndecomposition\nmaximum depth: 3\n" + rules, 1) == "ED");
    CHECK(derived("axiom: S\ndecomposition\nmaximum depth: 2\n" + rules, 1) == "CD");
    CHECK(derived("axiom: S\ndecomposition\n" + rules, 1) == "AB");
  }
  SECTION("homomorphism: at depth 0 over the whole string") {
    CHECK(interpreted("axiom: ABABC\nhomomorphism\nA B --> F\n") == "FFC");
    CHECK(interpreted("axiom: A(1)B(2)\nhomomorphism\nA(x) B(y) --> F(x * y)\n") == "F(2)");
  }
  SECTION("homomorphism: inside one successor, recursively") {
    CHECK(interpreted("axiom: S\nhomomorphism\nmaximum depth: 2\nS --> ABG\nA B --> X\n") == "XG");
    CHECK(interpreted("axiom: S\nhomomorphism\nS --> ABG\nA B --> X\n") == "ABG");
  }
  SECTION("homomorphism: a successor's end ends the match; a module drawn is not rewritten later") {
    // P --> A and Q --> B are two successors.
    CHECK(interpreted("axiom: PQ\nhomomorphism\nmaximum depth: 2\nP --> A\nQ --> B\nA B --> X\n") == "AB");
    // A meets C at depth 0 and is drawn; C --> B at depth 1 does not make A B.
    CHECK(interpreted("axiom: AC\nhomomorphism\nmaximum depth: 2\nC --> B\nA B --> X\n") == "AB");
  }
  SECTION("a query module in a homomorphism predecessor, first or later, is an error at it") {
    CHECK(errorOf("axiom: A\nhomomorphism\nA ?P(x,y,z) --> F\n") ==
          "t.l:3:3: cpfg's query module '?P' in an interpretation rule is not supported (its values would be lost with "
          "the interpreted string)");
  }
  SECTION("homomorphism successors are not decomposed (cpfg's InterpretHomomorphism skips decomposition)") {
    CHECK(interpreted("axiom: A\ndecomposition\nB --> X\nhomomorphism\nA --> B\n") == "B");
    CHECK(derived("axiom: A\ndecomposition\nB --> X\nhomomorphism\nA --> B\n", 0) == "A");
  }
}

TEST_CASE("cpfg's C preprocessor", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/preprocessor: macros, #ifdef, #include (derived by hand in its comment)") {
    Grammar g = loadGrammar(cpfgAsset("preprocessor/plant.l"));
    Deriver d(g);
    CHECK(formatModuleString(d.derive(), d.symbols(), FormatOptions{0, true}) == "F(1)[+(30)F(0.5)@o(0.2)]F(1)[+(30)F(0.5)@o(0.2)]A");
    CHECK(g.define("LATERAL").value() == 0.5);  // a number stays a constant -D may override
  }
  SECTION("an error in an included file is at its own file:line:col") {
    const std::string file = cpfgAsset("preprocessor_errors/plant.l");
    CHECK(errorOf(readFile(file), file) == cpfgAsset("preprocessor_errors/rules.h") +
                                                    ":2:8: cpfg's '@bo' (circle boundary) is not supported");
  }
  SECTION("an error inside a macro's expansion is at the macro's use") {
    CHECK(errorOf("#define LEAF [@bo(1)]\naxiom: F LEAF\n") == "t.l:2:10: cpfg's '@bo' (circle boundary) is not supported");
    CHECK(errorOf("#define B(x) F(x)\naxiom: A B(1, 2) C\n") ==
          "t.l:2:10: macro 'B' takes 1 argument(s) (defined at t.l:1), or its expansion nests deeper than 64 levels");
    // Columns after an expansion are the file's own.
    CHECK(errorOf("#define S F(1)F(1)\naxiom: S@bo(1)\n") == "t.l:2:9: cpfg's '@bo' (circle boundary) is not supported");
  }
  SECTION("cpp's line splicing: a directive ending in a backslash goes on with the next line") {
    Grammar g = parseGrammar("#define LEAF [+F \\\n\t-F] \\\n  G\n#define N 1 + \\\n 2\naxiom: A LEAF F(N)\n", "t.l");
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "A[+F-F]GF(3)");
    // The lines a directive took are blank: later lines keep their numbers.
    CHECK(errorOf("#define LEAF [+F \\\n\t-F]\naxiom: A LEAF @bo(1)\n") == "t.l:3:15: cpfg's '@bo' (circle boundary) is not supported");
  }
  SECTION("cpp's identifiers: a macro named B is not expanded inside AB; a number body stays a value") {
    Grammar g = parseGrammar("#define B [+F]\n#define N (2 + 1)\naxiom: AB B F(N)\n", "t.l");
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "AB[+F]F(3)");
  }
  SECTION("cpp's textual substitution: an unparenthesized body binds as written") {
    // #define K 1+2: 2*K is 2*1+2 = 4 in cpfg (cpp), not 6.
    Grammar g = parseGrammar("#define K 1+2\naxiom: A(2*K)\n", "t.l");
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "A(4)");
  }
  SECTION("errors") {
    CHECK(errorOf("#include \"../query/plant.v\"\naxiom: A\n", cpfgAsset("preprocessor/t.l")).find(
              ":1:10: '#include \"../query/plant.v\"' is outside the object's folder") != std::string::npos);
    CHECK(errorOf("#include \"missing.h\"\naxiom: A\n") == "t.l:1:10: cannot find file 'missing.h'");
    CHECK(errorOf("#ifdef X\naxiom: A\n") == "t.l:1:1: '#if' block without '#endif'");
    CHECK(errorOf("axiom: A\n#endif\n") == "t.l:2:1: '#endif' without '#ifdef' or '#ifndef'");
    CHECK(errorOf("#define B F\n#define B G\naxiom: A\n") == "t.l:2:9: 'B' is already defined at t.l:1");
    CHECK(errorOf("#define B F\n#undef B\n#define B G\naxiom: B\n") == "no error");
  }
}

TEST_CASE("cpfg sub-L-systems: calls derived by their own L-system", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/sub_lsystem: each call derived by its own L-system (strings by hand in plant.l)") {
    Drawn o = drawObject("sub_lsystem", true);
    CHECK(o.string ==
          "F(1)F(1)F(1)BF(1)[+?(2,0.5)F(2)?(3,2)F(4)D$F(2)?(3,2)D$BEE$]F(1)[+?(2,0.5)F(2)?(3,2)D$BE$]F(1)[+?(2,0.5)B$]A");
    // The view file's 90 degrees; ?(2, 0.5) halves lengths and widths, ?(3, 2) inside it
    // doubles them back: F(2) is 1 long, F(4) 4 long (0.5 * 2 * 4).
    const std::vector<std::pair<DVec3, DVec3>> want = {
        {{0, 0, 0}, {0, 1, 0}},   {{0, 1, 0}, {0, 2, 0}},   {{0, 2, 0}, {0, 3, 0}},   {{0, 3, 0}, {0, 4, 0}},
        {{0, 4, 0}, {-1, 4, 0}},  {{-1, 4, 0}, {-5, 4, 0}}, {{-5, 4, 0}, {-6, 4, 0}}, {{0, 4, 0}, {0, 5, 0}},
        {{0, 5, 0}, {-1, 5, 0}},  {{0, 5, 0}, {0, 6, 0}}};
    checkSegments(o.skeleton, want);
    // Widths: 0.2 on the main axis, 0.1 in L-system 2, 0.2 again in L-system 3 (x 0.5 x 2).
    const double r0 = o.skeleton.internodes[0].baseRadius;
    REQUIRE(r0 > 0);
    CHECK(o.skeleton.internodes[4].baseRadius == Approx(0.5 * r0));
    CHECK(o.skeleton.internodes[5].baseRadius == Approx(r0));
    CHECK(o.skeleton.internodes[6].baseRadius == Approx(0.5 * r0));
    CHECK(o.skeleton.internodes[7].baseRadius == Approx(r0));  // `]` restored the main width
    CHECK(o.skeleton.internodes[8].baseRadius == Approx(0.5 * r0));
  }
  SECTION("tests/assets/cpfg/sub_lsystem_include: the sub-L-system and its #define in an included file") {
    Grammar g = loadGrammar(cpfgAsset("sub_lsystem_include/plant.l"));
    Deriver d(g);
    CHECK(formatModuleString(d.step(), d.symbols()) == "F(1)[?(2,0.5)L(1)$]A");
    // Inside the call L is L-system 2's (x * RATE), never the main one's (x + 100).
    CHECK(formatModuleString(d.step(), d.symbols()) == "F(1)[?(2,0.5)L(2)$]F(1)[?(2,0.5)L(1)$]A");
    CHECK(g.define("RATE") == 2.0);
  }
  SECTION("a call back into the main L-system by its number; a cut ends at the call's '$'") {
    Grammar g = parseGrammar("lsystem: 1\nderivation length: 2\naxiom: ?(2)AB$A\nA --> AX\nendlsystem\n"
                             "lsystem: 2\nA --> ?(1)A$%B\nB --> C\nendlsystem\n",
                             "t.l");
    Deriver d(g);
    // Step 1: inside L-system 2, A --> ?(1)A$%B and B --> C; outside, A --> AX. The cut
    // waits for step 2, which removes %BC up to the call's $ (not to the end of the string).
    CHECK(formatModuleString(d.step(), d.symbols()) == "?(2)?(1)A$%BC$AX");
    // Step 2: the inner A is in L-system 1 again.
    CHECK(formatModuleString(d.step(), d.symbols()) == "?(2)?(1)AX$$AXX");
  }
}

TEST_CASE("cpfg sub-L-systems: each L-system's decomposition and interpretation rules", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/sub_lsystem_rules: each L-system's decomposition, interpretation and ignore: inside its calls") {
    Grammar g = loadGrammar(cpfgAsset("sub_lsystem_rules/plant.l"));
    CHECK(g.hasInterpretation());
    Deriver d(g);
    CHECK(formatModuleString(d.current(), d.symbols()) == "A");
    CHECK(formatModuleString(d.step(), d.symbols()) == "II[+?(2,0.5)B$]A");
    CHECK(formatModuleString(d.step(), d.symbols()) == "IIII[+?(2,0.5)IWZK+B$]II[+?(2,0.5)B$]A");
    const ModuleString& s = d.step();
    CHECK(formatModuleString(s, d.symbols()) == "IIIIIIII[+?(2,0.5)IWZK+Q$]IIII[+?(2,0.5)IWZK+B$]II[+?(2,0.5)B$]A");
    const ModuleString shown = d.interpret(s);
    CHECK(formatModuleString(shown, d.symbols()) ==
          "F(1)F(1)F(1)F(1)F(1)F(1)F(1)F(1)[+?(2,0.5)IF(2)?(3,2)F(5)$F(3)K+Q$]F(1)F(1)F(1)F(1)"
          "[+?(2,0.5)IF(2)?(3,2)F(5)$F(3)K+B$]F(1)F(1)[+?(2,0.5)B$]A");
    // Drawn with the view file's 90 degrees: L-system 2 at half scale, L-system 3 inside it
    // at twice that (F(5) is 5 long), back to half after its '$' (F(3) is 1.5 long).
    Drawn o = drawObject("sub_lsystem_rules", true);
    std::vector<std::pair<DVec3, DVec3>> want;
    auto axis = [&](double y0, int n) {
      for (int k = 0; k < n; ++k) want.push_back({{0, y0 + k, 0}, {0, y0 + k + 1, 0}});
    };
    auto branch = [&](double y) {
      want.push_back({{0, y, 0}, {-1, y, 0}});
      want.push_back({{-1, y, 0}, {-6, y, 0}});
      want.push_back({{-6, y, 0}, {-7.5, y, 0}});
    };
    axis(0, 8);
    branch(8);
    axis(8, 4);
    branch(12);
    axis(12, 2);
    checkSegments(o.skeleton, want);
    const double r0 = o.skeleton.internodes[0].baseRadius;
    REQUIRE(r0 > 0);
    CHECK(o.skeleton.internodes[8].baseRadius == Approx(0.5 * r0));
    CHECK(o.skeleton.internodes[9].baseRadius == Approx(r0));
    CHECK(o.skeleton.internodes[10].baseRadius == Approx(0.5 * r0));
  }
  SECTION("interpretation: each L-system's own maximum depth, and the rules of the L-system current at each module") {
    const std::string head = "lsystem: 1\naxiom: W?(2)W$W\nhomomorphism\nmaximum depth: 5\nW --> V\nV --> F(1)\nendlsystem\n"
                             "lsystem: 2\nhomomorphism\nW --> ?(3)I$V\nendlsystem\nlsystem: 3\nhomomorphism\n";
    // Inside call 2, W --> ?(3)I$V at depth 0; I at depth 1 is L-system 3's, whose
    // maximum depth (1 by default) stops it; V after the '$' is L-system 2's, which has no
    // rule for it: only the main L-system's W's become F(1) (two levels).
    Grammar shallow = parseGrammar(head + "I --> F(5)\nendlsystem\n", "t.l");
    Deriver a(shallow);
    CHECK(formatModuleString(a.interpret(a.current()), a.symbols()) == "F(1)?(2)?(3)I$V$F(1)");
    Grammar deep = parseGrammar(head + "maximum depth: 2\nI --> F(5)\nendlsystem\n", "t.l");
    Deriver b(deep);
    CHECK(formatModuleString(b.interpret(b.current()), b.symbols()) == "F(1)?(2)?(3)F(5)$V$F(1)");
    // A rule that replaces the call itself: the turtle never reaches the '?(2)', so what
    // follows stays in the main L-system (cpfg switches on the modules it draws).
    Grammar replaced = parseGrammar("lsystem: 1\naxiom: ?(2)W$\nhomomorphism\n?(n) --> G\nW --> F(1)\nendlsystem\n"
                                    "lsystem: 2\nhomomorphism\nW --> F(2)\nendlsystem\n",
                                    "t.l");
    Deriver c(replaced);
    CHECK(formatModuleString(c.interpret(c.current()), c.symbols()) == "GF(1)$");
  }
  SECTION("decomposition: the axiom in step 1, each module by the L-system it is in") {
    Grammar g = parseGrammar("lsystem: 1\nderivation length: 1\naxiom: X?(2)X$X\nX --> XX\ndecomposition\nX --> Y\nendlsystem\n"
                             "lsystem: 2\nX --> X\ndecomposition\nmaximum depth: 2\nX --> ZX\nendlsystem\n",
                             "t.l");
    Deriver d(g);
    // cpfg does not decompose the axiom before the first step.
    CHECK(formatModuleString(d.current(), d.symbols()) == "X?(2)X$X");
    // Step 1: X --> XX and X --> Y outside; X --> X and X --> ZX twice (depth 2) inside.
    CHECK(formatModuleString(d.step(), d.symbols()) == "YY?(2)ZZX$YY");
    // Y, Z have no productions; the inner X --> X is decomposed by L-system 2 again.
    CHECK(formatModuleString(d.step(), d.symbols()) == "YY?(2)ZZZZX$YY");
  }
}

TEST_CASE("cpfg sub-L-systems: errors", "[lsystem][cpfg]") {
  SECTION("errors") {
    CHECK(errorOf("axiom: ?(2)A$\nendlsystem\nlsystem: 2\nseed: 3\nA --> B\n") ==
          "t.l:4:1: 'seed:' in a sub-L-system ('lsystem: 2') is not supported (Sprig reads a sub-L-system's productions, "
          "decomposition and interpretation rules and 'ignore:' or 'consider:')");
    CHECK(errorOf("axiom: ?(2)A$\nendlsystem\nlsystem: 2\nignore: F\nignore: G\nA --> B\n") ==
          "t.l:5:1: duplicate 'ignore:' (first at line 4)");
    CHECK(errorOf("axiom: ?(2)A$\nendlsystem\nlsystem: 2\nhomomorphism\nA --> ?P(1,2)\n") ==
          "t.l:5:7: cpfg's query module '?P' in an interpretation rule is not supported (its values would be lost with the "
          "interpreted string)");
    CHECK(errorOf("axiom: ?(2)A$\nignore: F\nendlsystem\nlsystem: 2\nignore: F\nA --> B\n") == "no error");
    CHECK(errorOf("axiom: A\nendlsystem\nlsystem: 2\nendlsystem\nlsystem: 2\n") ==
          "t.l:5:1: 'lsystem: 2' is defined twice (first at line 3)");
    CHECK(errorOf("axiom: ?(2)A$\nendlsystem\nlsystem: 2\nA --> B\n", "t.lsys") ==
          "t.lsys:1:8: cpfg's '?(n, scale)' (sub-L-system call) is supported only in cpfg's notation (a .l file), where '$' ends it");
    CHECK(errorOf("axiom: ?(2,1,3)A$\n") == "t.l:1:8: cpfg's sub-L-system call '?(n, scale)' takes 1 or 2 parameters, got 3");
    // A number computed at derivation time: the error comes then.
    Grammar g = parseGrammar("#define N 5\naxiom: ?(N)A$\nA --> B\nendlsystem\nlsystem: 2\nA --> C\n", "t.l");
    try {
      Deriver d(g);
      d.step();
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().message ==
            "'?(5, ...)' at step 1 calls a sub-L-system the file does not define (its L-systems: 2)");
    }
  }
}

TEST_CASE("cpfg srand and stop", "[lsystem][cpfg]") {
  const std::string rules = "derivation length: 4\naxiom: A(0)\nA(x) --> A(ran(1))A(x) : 1\nA(x) --> B : 1\n";
  SECTION("srand(s) in Start: reseeds cpfg's erand48 stream to {0x330E, s & 0xFFFF, s >> 16}") {
    Grammar g = parseGrammar("derivation length: 1\nStart: {srand(70000);}\naxiom: A(0)\nA(x) --> A(ran(1))A(ran(2))\n", "t.l");
    Rand48 r = Rand48::fromWords(0x330E, 70000 & 0xFFFF, 70000 >> 16);
    const double a = r.next(), b = 2 * r.next();
    const ModuleString s = derive(g);
    CHECK(s.params[0] == static_cast<double>(static_cast<float>(a)));
    CHECK(s.params[1] == static_cast<double>(static_cast<float>(b)));
    Grammar unseeded = parseGrammar("derivation length: 1\naxiom: A(0)\nA(x) --> A(ran(1))\n", "t.l");
    Rand48 start = Rand48::fromWords(0x330E, 0, 0);  // cpfg's stream before any srand
    CHECK(derive(unseeded).params[0] == static_cast<double>(static_cast<float>(start.next())));
    // Unlike 'seed: 7', which makes the L-system stochastic and leaves erand48 alone.
    Grammar reseeded = parseGrammar("Start: {srand(7);}\n" + rules, "t.l");
    Grammar seeded = parseGrammar("seed: 7\n" + rules, "t.l");
    CHECK(formatModuleString(derive(reseeded), reseeded.symbols()) != formatModuleString(derive(seeded), seeded.symbols()));
  }
  SECTION("srand in StartEach: reseeds before every step, so every step draws alike") {
    Grammar g = parseGrammar("derivation length: 3\nStartEach: {srand(3);}\naxiom: A(0)\nA(x) --> A(ran(1))\n", "t.l");
    Deriver d(g);
    const double first = d.step().params[0];
    CHECK(d.step().params[0] == first);
    CHECK(d.step().params[0] == first);
  }
  SECTION("srand in a production reseeds for the modules after it, in string order") {
    Grammar g = parseGrammar("derivation length: 1\naxiom: A(0)B(0)A(0)\nA(x) --> A(ran(1))\nB(x) : {srand(3);} * --> B(0)\n", "t.l");
    const ModuleString s = derive(g);
    Rand48 before = Rand48::fromWords(0x330E, 0, 0), after = Rand48::fromWords(0x330E, 3, 0);
    CHECK(s.params[0] == static_cast<double>(static_cast<float>(before.next())));
    CHECK(s.params[2] == static_cast<double>(static_cast<float>(after.next())));
  }
  SECTION("stop(x) in a production ends the derivation after the current step") {
    Grammar g = parseGrammar("derivation length: 10\naxiom: A(0)\nA(n) : {if (n == 2) {stop(1);}} * --> F A(n+1)\n", "t.l");
    Deriver d(g);
    // Step 3 rewrites A(2), which calls stop: A(3) after step 3, and no step 4.
    CHECK(formatModuleString(d.derive(), d.symbols()) == "FFFA(3)");
    CHECK(d.stepsDone() == 3);
    CHECK(d.steps() == 3);
    d.restart();
    CHECK(d.steps() == 10);
  }
  SECTION("stop in EndEach: over a global; End: still runs after the last step") {
    Grammar g = parseGrammar("derivation length: 10\nStart: {k = 0;}\nEndEach: {k = k + 1; if (k == 2) {stop(0);}}\n"
                             "End: {printf(\"\");}\naxiom: A\nA --> FA\n",
                             "t.l");
    Deriver d(g);
    CHECK(formatModuleString(d.derive(), d.symbols()) == "FFA");
  }
  SECTION("errors") {
    CHECK(errorOf("axiom: A\nA : {srand(2);} * --> B\n") == "no error");
    CHECK(errorOf("axiom: A\nhomomorphism\nA : {srand(2);} * --> F\n") == "no error");
    CHECK(errorOf("axiom: A\nA : {srand(2);} * --> B\n", "t.lsys") ==
          "t.lsys:2:6: cpfg's function 'srand' is supported only as a statement ('srand(s);') of a 'Start:', 'StartEach:', "
          "'EndEach:' or 'End:' block, or of a rule's statements in a .l file (where it reseeds cpfg's own random stream)");
    CHECK(errorOf("axiom: A\nA : stop(1) --> B\n") == "t.l:2:5: cpfg's function 'stop' is supported only as a statement ('stop(1);')");
    CHECK(errorOf("axiom: A\nhomomorphism\nA : {stop(1);} * --> F\n") ==
          "t.l:3:6: cpfg's function 'stop' in an interpretation rule is not supported (the derivation has ended when the "
          "string is interpreted): call it in a production or a Start/EndEach block");
  }
}

TEST_CASE("cpfg function files and func(n, x)", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/function: values from its reference.py (scipy's B-splines)") {
    const ViewFile view = loadViewFile(cpfgAsset("function/plant.v"));
    REQUIRE(view.functions.size() == 3);
    CHECK(view.functions[0].samples() == 0);  // fver files keep their own samples
    CHECK(view.functions[1].samples() == 5);  // the range: format takes the view file's
    CHECK(view.functions[2].samples() == 0);
    CHECK(view.functions[2].points().size() == 5);  // the multiplicity 2 doubles a point
    GrammarOverrides o;
    o.cpfgFunctions = view.functions;
    const std::string file = cpfgAsset("function/plant.l");
    Grammar g = parseGrammar(readFile(file), file, o);
    const ModuleString s = derive(g);
    REQUIRE(s.size() == 4);
    const std::vector<double> want = {0.15625, 0.783014893532, 0.000002859160, 0.999997140840,
                                      0.570114535667, 0.434987995268, 0.066938758886, 2.0};
    std::vector<double> got;
    for (size_t i = 0; i < s.size(); ++i)
      for (double v : s.paramsOf(i)) got.push_back(v);
    REQUIRE(got.size() == want.size());
    for (size_t k = 0; k < want.size(); ++k) CHECK(got[k] == Approx(want[k]).margin(1e-9));
  }
  SECTION("a four-point function is a Bezier segment: its ends are the first and last points") {
    CpfgFunction f = CpfgFunction::parse("range: 0 1\npoints: 4\n0 0.5\n0.3 2\n0.6 -1\n1 0.25\n", "f.func", -1);
    CHECK(f.point(0).y == Approx(0.5));
    CHECK(f.point(0.999999).y == Approx(0.25).margin(1e-5));
    // Bezier: y(1/2) = (0.5 + 3 * 2 + 3 * (-1) + 0.25) / 8, at x(1/2) = (0 + 0.9 + 1.8 + 1) / 8.
    CHECK(f.point(0.5).y == Approx(3.75 / 8));
    CHECK(f.point(0.5).x == Approx(3.7 / 8).epsilon(1e-6));
  }
  SECTION("errors") {
    auto errorIn = [](const std::string& text) {
      return firstError([&] { CpfgFunction::parse(text, "f.func", -1); }, true);
    };
    CHECK(errorIn("range: 0 1\npoints: 3\n0 0\n0.5 1\n1 0\n") ==
          "f.func:2:1: a function needs at least 4 points ('points: n', n from 4 to 100000)");
    CHECK(errorIn("range: 0 1\npoints: 4\n0 0\n0.5 x1\n0.7 1\n1 0\n") == "f.func:4:5: expected a number, got 'x1'");
    CHECK(errorIn("fver 2 0\n") == "f.func:1:1: function file version 2.0 is not supported (cpfg reads 'fver 1 1' and the 'range:' format)");
    CHECK(errorIn("range: 0 1\npoints: 4\n0.2 0\n0.5 1\n0.7 1\n1 0\n").find(
              "f.func:2:1: the function's x does not increase from 0 to 1 along its curve") == 0);
    CHECK(errorIn("range: 0 1\npoints: 5\n0 0\n0.5 1\n") == "f.func:4:1: the function file ends after 2 of its 5 points");
    CHECK(errorOf("axiom: A(func(1, 0.5))\n") ==
          "t.l:1:10: cpfg's func(n, x) reads the view file's function files, and it names none ('function: NAME.func')");
    CHECK(viewErrorOf("function: missing.func\n") == "t.v:1:11: cannot find file 'missing.func'");
    CHECK(viewErrorOf("function: ../x.func\n") ==
          "t.v:1:11: the function file '../x.func' is outside the object's folder (only files beside the view file, or in folders below it)");
  }
}

TEST_CASE("cpfg generalized cylinders", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/generalized_cylinder: pieces from its reference.py (Hermite basis)") {
    Drawn o = drawObject("generalized_cylinder", true);
    struct Piece {
      DVec3 a, b;
      double ra, rb;
    };
    const std::vector<Piece> want = {
        {{0, 0, 0}, {0, 1, 0}, 0.1, 0.1},
        {{0, 1, 0}, {0, 2, 0}, 0.1, 0.1},
        {{0, 2, 0}, {-0.2, 2.3375, 0}, 0.1, 0.125},
        {{-0.2, 2.3375, 0}, {-0.7, 2.3, 0}, 0.125, 0.15},
        {{-0.7, 2.3, 0}, {-1.35, 2.1125, 0}, 0.15, 0.175},
        {{-1.35, 2.1125, 0}, {-2, 2, 0}, 0.175, 0.2}};
    REQUIRE(o.skeleton.internodes.size() == want.size());  // f draws nothing: only the tube
    for (size_t k = 0; k < want.size(); ++k) {
      INFO("piece " << k);
      const Internode& in = o.skeleton.internodes[k];
      checkNear(in.start, want[k].a);
      checkNear(in.end, want[k].b);
      CHECK(in.baseRadius == Approx(want[k].ra));
      CHECK(in.tipRadius == Approx(want[k].rb));
      CHECK(in.parent == static_cast<int32_t>(k) - 1);  // one chain
    }
  }
  SECTION("@Gc without a parameter draws cpfg's 4 rings; [ ] saves the cylinder; @Gt sets the tangents") {
    // The branch continues the cylinder from (0,1) and ends it; after ] the outer one goes
    // on from (0,1) too: two segments of 4 rings and one of 1.
    Grammar g = parseGrammar("axiom: @Gs f(1) @Gc [ + f(1) @Ge ] f(1) @Ge(1)\n", "t.l");
    ViewFile view = parseViewFile("angle increment: 90\ninitial line width: 0.2 polygon\n", "t.v");
    Skeleton sk = Turtle(g.symbols(), cpfgTurtleSettings(&view, {})).run(g.axiom());
    REQUIRE(sk.internodes.size() == 9);
    checkNear(sk.internodes[7].end, DVec3(-1, 1, 0));   // the branch's end
    checkNear(sk.internodes[8].start, DVec3(0, 1, 0));  // the outer cylinder resumes at (0,1)
    checkNear(sk.internodes[8].end, DVec3(0, 2, 0));
    CHECK(sk.internodes[8].parent == 3);
    // @Gt(0, 0): zero tangents make the segment straight: its mid ring on the chord.
    Grammar s = parseGrammar("axiom: @Gt(0) @Gs f(1) + f(1) @Ge(2)\n", "t.l");
    Skeleton straight = Turtle(s.symbols(), cpfgTurtleSettings(&view, {})).run(s.axiom());
    REQUIRE(straight.internodes.size() == 2);
    checkNear(straight.internodes[0].end, DVec3(-0.5, 0.5, 0));  // the chord (0,0)-(-1,1)
  }
}

TEST_CASE("cpfg surface files: the placed patch, precisions and cpfg's frame map", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/surface: a bilinear patch placed after F(3) and a right turn, by hand") {
    // plate.s is the bilinear patch x = 1 + 3t, y = 3s, z = 9st (Bezier points at thirds).
    // Contact (1,0,0), SIZE 3, view size 6: p = 2 (f - contact) = (6t, 6s, 18st) in the
    // surface frame (heading +Y, up +Z, left = heading x up = +X). The turtle is at (0,3,0)
    // with H = +X, L = +Y, cpfg's up (0,0,-1); ~a(0.5) puts p at
    // (0,3,0) + 0.5 (p.x L + p.y H + p.z up) = (3s, 3 + 3t, -9st).
    const Drawn o = drawObject("surface", true);
    REQUIRE(o.skeleton.organs.size() == 1);
    const Organ& sf = o.skeleton.organs[0];
    CHECK(sf.kind == Organ::Kind::Surface);
    CHECK(sf.name == "a");
    // The view file's precisions: s 3, t 2: 4 x 3 vertices, 3 x 2 cells of 2 triangles.
    REQUIRE(sf.points.size() == 12);
    REQUIRE(sf.normals.size() == 12);
    REQUIRE(sf.triangles.size() == 36);
    for (int si = 0; si <= 3; ++si)
      for (int ti = 0; ti <= 2; ++ti) {
        const double s = si / 3.0, t = ti / 2.0;
        const size_t k = static_cast<size_t>(si * 3 + ti);
        INFO("vertex s = " << s << ", t = " << t);
        checkNear(sf.points[k], DVec3(3 * s, 3 + 3 * t, -9 * s * t));
        // dP/dt x dP/ds = (-108s, -108t, 36) in the surface frame, (-108t, -108s, -36) placed.
        checkNear(sf.normals[k], glm::normalize(DVec3(-108 * t, -108 * s, -36)));
      }
    for (size_t k = 0; k < sf.triangles.size(); k += 3) {
      const DVec3 a = sf.points[sf.triangles[k]], b = sf.points[sf.triangles[k + 1]], c = sf.points[sf.triangles[k + 2]];
      const DVec3 n = sf.normals[sf.triangles[k]] + sf.normals[sf.triangles[k + 1]] + sf.normals[sf.triangles[k + 2]];
      CHECK(glm::dot(glm::cross(b - a, c - a), n) > 0);  // wound as the normals point
    }
    // The end point (1,3,0) is p = (0,6,0): the turtle moves 0.5 * 6 along H to (3,3,0).
    REQUIRE(o.skeleton.internodes.size() == 2);
    checkNear(o.skeleton.internodes[0].end, DVec3(0, 3, 0));
    checkNear(o.skeleton.internodes[1].start, DVec3(3, 3, 0));
    checkNear(o.skeleton.internodes[1].end, DVec3(4, 3, 0));
    checkNear(o.end.frame.position, DVec3(4, 3, 0));
  }
  SECTION("precisions: the view file's, else the file's S precision for both, else 5") {
    const std::string text = readFile(cpfgAsset("surface/plate.s"));
    CpfgSurface a = CpfgSurface::parse(text, "plate.s", 3, 0, 0);
    CHECK(a.sPrecision() == 7);
    CHECK(a.tPrecision() == 7);  // cpfg reads 'T: 9' and uses S for both
    CHECK(a.vertices().size() == 64);
    std::string noPrecision = text;
    noPrecision.erase(noPrecision.find("PRECISION"), std::string("PRECISION S: 7 T: 9\n").size());
    CpfgSurface b = CpfgSurface::parse(noPrecision, "plate.s", 3, 0, 0);
    CHECK(b.sPrecision() == 5);
    CHECK(b.tPrecision() == 5);
    // size 3 = SIZE: the patch is the file's, moved so that the contact point is the origin.
    checkNear(b.point(0, 1.0, 1.0), DVec3(3, 3, 9));
    checkNear(b.point(0, 0.5, 0.5), DVec3(1.5, 1.5, 9 * 0.25));
  }
  SECTION("cpfg's frame map: p = x left + y heading + z up, with left = heading x up") {
    // HEADING +X, UP +Z: left = (0,-1,0); f - contact = (3,0,0) goes to 3 * left = (0,-3,0)
    // (cpfg's patches.c; the transposed map would give (0,3,0)).
    std::string text = readFile(cpfgAsset("surface/plate.s"));
    text.replace(text.find("HEADING  X: 0 Y: 1"), std::string("HEADING  X: 0 Y: 1").size(), "HEADING  X: 1 Y: 0");
    CpfgSurface s = CpfgSurface::parse(text, "plate.s", 3, 2, 2);
    checkNear(s.point(0, 0.0, 1.0), DVec3(0, -3, 0));  // P[0][3] = (4,0,0)
    checkNear(s.point(0, 1.0, 0.0), DVec3(3, 0, 0));   // P[3][0] = (1,3,0): 3 * heading
    checkNear(s.endPoint(), DVec3(3, 0, 0));
  }
}

TEST_CASE("cpfg ~X: scales, undefined surfaces; surface file errors and missing files", "[lsystem][cpfg]") {
  SECTION("~X(sx, sy, sz) scales each axis; the end point moves by sx; a zero scale draws nothing") {
    ViewFile view = loadViewFile(cpfgAsset("surface/plant.v"));
    GrammarOverrides go;
    go.cpfgSurfaceIds = "a";
    Grammar g = parseGrammar("axiom: ~a(1, 2, -1) F ~a(0) F\n", "t.l", go);
    Skeleton sk = Turtle(g.symbols(), cpfgTurtleSettings(&view, {})).run(g.axiom());
    REQUIRE(sk.organs.size() == 1);
    // At the origin, H = +Y, L = -X, cpfg's up (0,0,-1): p (6t, 6s, 18st) goes to
    // (-6t, 2 * 6s, 18st) and the end point (0,6,0) moves the turtle 6 along H.
    checkNear(sk.organs[0].points[11], DVec3(-6, 12, 18));  // s = 1, t = 1
    REQUIRE(sk.internodes.size() == 2);
    checkNear(sk.internodes[0].start, DVec3(0, 6, 0));
    checkNear(sk.internodes[1].start, DVec3(0, 7, 0));  // ~a(0): nothing drawn, no move
  }
  SECTION("~X the view file does not define draws nothing, as in cpfg: a warning; a tsurface's ~X is an error") {
    GrammarOverrides go;
    go.cpfgSurfaceIds = "ab";
    go.cpfgUndrawnSurfaceIds = "t";
    const Grammar g = parseGrammar("axiom: F ~c(2) F ~c\n", "t.l", go);
    REQUIRE(g.warnings().size() == 1);  // once per id
    CHECK(g.warnings()[0].loc.col == 10);
    CHECK(g.warnings()[0].message == "cpfg's '~c' names no surface (the view file has no 'surface: c ...' line; it defines "
                                     "'ab'): it draws nothing, as in cpfg");
    // Drawn: the two F and nothing else; ~c does not move the turtle (patches.c, determine_end_point).
    const Skeleton sk = interpret(derive(g), g.symbols(), cpfgTurtleSettings(nullptr, TurtleSettings{}));
    REQUIRE(sk.internodes.size() == 2);
    CHECK(sk.organs.empty());
    CHECK(sk.internodes[1].start.y == Approx(sk.internodes[0].end.y));
    try {
      parseGrammar("axiom: F ~t\n", "t.l", go);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().message ==
            "cpfg's '~t' names the view file's 'tsurface: t ...' (a triangulated surface), which is not supported");
    }
    CHECK(parseViewFile("tsurface: t leaf.ts\n", "t.v").tsurfaceIds == "t");
  }
  SECTION("errors: malformed surface files and surface: lines") {
    const std::string text = readFile(cpfgAsset("surface/plate.s"));
    auto surfaceError = [&](std::string from, std::string to) {
      std::string t = text;
      t.replace(t.find(from), from.size(), to);
      return firstError([&] { CpfgSurface::parse(t, "p.s", 1, 0, 0); }, false);
    };
    CHECK(surfaceError("SIZE: 3", "SIZE: 0") == "7:1: the surface's SIZE must be greater than 0");
    CHECK(surfaceError("SIZE: 3", "SIZE 3") == "7:1: expected 'SIZE:' (the surface's size), got 'SIZE'");
    CHECK(surfaceError("UP  X: 0 Y: 0 Z: 1", "UP  X: 0 Y: 2 Z: 0") == "5:1: the surface's HEADING and UP must be nonzero and not parallel");
    CHECK(surfaceError("2 1 1", "2 one 1") == "14:10: expected a number (a control point's y), got 'one'");
    CHECK(surfaceError("4 3 9\n", "4 3\n") == "16:25: the surface file ends before a control point's z");
    CHECK(surfaceError("L: ~ R: ~", "L: ~ R: leaf") == "11:9: no patch 'leaf' in the file for patch 'plate''s R:");
    CHECK(surfaceError("L: ~ R: ~", "L: ~ R: plate") == "11:9: patch 'plate' is 'plate''s R: but its L: is '~'");
    CHECK(surfaceError("PRECISION S: 7", "PRECISION S: 11") == "2:14: a surface's precision is 1 to 10, got 11");
    CHECK(viewErrorOf("surface: ab plate.s\n") == "t.v:1:10: a surface's id is one character (the letter after '~'), got 'ab'");
    CHECK(viewErrorOf("surface: a\n") == "t.v:1:10: expected 'surface: X FILE.s [size [s-precision t-precision] [texture]]'");
    CHECK(viewErrorOf("surface: ~ seg.s 1\n") == "t.v:1:10: cpfg's surface id '~' (a surface only '~~' would draw) is not supported");
    CHECK(viewErrorOf("surface: a ../x.s 1\n") == "t.v:1:12: the surface file '../x.s' is outside the object's folder (only files beside the view file, or in folders below it)");
    CHECK(viewErrorOf("surface: a x.s big\n") == "t.v:1:16: expected the surface's size (a number), got 'big'");
  }
  SECTION("a surface file that does not exist: the line is skipped with a warning, as cpfg skips it (vlab's Sedge)") {
    const ViewFile v = parseViewFile("surface: b no_such_bract.s 1.5 3 3\n", "t.v");
    CHECK(v.surfaces.empty());
    REQUIRE(v.warnings.size() == 1);
    CHECK(v.warnings[0].loc.col == 12);
    CHECK(v.warnings[0].message == "the surface file 'no_such_bract.s' does not exist: the line is skipped, as cpfg skips it");
  }
}

TEST_CASE("cpfg line: defines a surface; F is drawn as without it", "[lsystem][cpfg]") {
  // interpret.c, case 20: 'line: L plate.s 4 2 2' reads plate.s as 'surface: L plate.s 4 2 2'
  // would; the line type it records is read by nothing (irisGL.c), so F stays a cylinder.
  const Drawn d = drawObject("line", true);
  REQUIRE(d.skeleton.internodes.size() == 1);
  checkNear(d.skeleton.internodes[0].start, DVec3(0, 0, 0));
  checkNear(d.skeleton.internodes[0].end, DVec3(0, 2, 0));
  CHECK(d.skeleton.internodes[0].baseRadius == Approx(0.05));
  REQUIRE(d.skeleton.organs.size() == 1);
  const Organ& o = d.skeleton.organs[0];
  CHECK(o.kind == Organ::Kind::Surface);
  checkNear(o.position, DVec3(0, 2, 0));
  // The same surface drawn through a 'surface:' line, vertex for vertex.
  const std::string dir = cpfgAsset("line");
  ViewFile surface = parseViewFile("surface: L plate.s 4 2 2\n", dir + "/s.v");
  REQUIRE(surface.surfaces.size() == 1);
  GrammarOverrides go;
  go.cpfgSurfaceIds = "L";
  const Grammar g = parseGrammar("axiom: F(2)~L\n", "t.l", go);
  const Skeleton sk = Turtle(g.symbols(), cpfgTurtleSettings(&surface, {})).run(g.axiom());
  REQUIRE(sk.organs.size() == 1);
  REQUIRE(sk.organs[0].points.size() == o.points.size());
  CHECK(o.points.size() == 9);  // one patch, 2 x 2 cells
  for (size_t k = 0; k < o.points.size(); ++k) checkNear(o.points[k], sk.organs[0].points[k]);
  CHECK(o.triangles == sk.organs[0].triangles);
}

TEST_CASE("cpfg curve files and curveX/Y/Z/GAL", "[lsystem][cpfg]") {
  SECTION("tests/assets/cpfg/curve: values from its reference.py (scipy's B-splines, cpfg's arc length)") {
    const ViewFile view = loadViewFile(cpfgAsset("curve/plant.v"));
    REQUIRE(view.curves.size() == 5);
    CHECK(view.curves[0].points().size() == 8);  // multiplicities 3, 1, 1, 3
    CHECK(view.curves[2].points().size() == 8);  // closed: 5 and the first 3 again
    CHECK(view.curves[4].points().size() == 6);  // phantom: 4 and a reflection at each end
    GrammarOverrides o;
    o.cpfgCurves = view.curves;
    const std::string file = cpfgAsset("curve/plant.l");
    Grammar g = parseGrammar(readFile(file), file, o);
    const ModuleString s = derive(g);
    const std::vector<double> want = {0.266539359281, -0.214051900902, 0.269398003817, 0.202474996448, 0.779429109754,
                                      3.099130240169, 2.993557034044,  1.003131285432, 0.680681990305, 9.351512374022,
                                      -0.940984014602, -0.692898328590, 4.930968087481, 2.866556877029, 0.623735391977,
                                      0.000000000000, 0.267827417490, 1.888500363212};
    std::vector<double> got;
    for (size_t i = 0; i < s.size(); ++i)
      for (double v : s.paramsOf(i)) got.push_back(v);
    REQUIRE(got.size() == want.size());
    for (size_t k = 0; k < want.size(); ++k) {
      INFO("value " << k);
      CHECK(got[k] == Approx(want[k]).margin(1e-9));
    }
  }
  SECTION("errors: no curve files, a wrong number, malformed curve files") {
    CHECK(errorOf("axiom: F(curveX(1, 0.5))\n") ==
          "t.l:1:10: cpfg's curveX reads the view file's curve files, and it names none ('curve: NAME.con')");
    GrammarOverrides o;
    o.cpfgCurves = loadViewFile(cpfgAsset("curve/plant.v")).curves;
    auto errorWith = [&](const std::string& text) {
      return firstError([&] { parseGrammar(text, "t.l", o); }, false);
    };
    CHECK(errorWith("axiom: F(curveGAL(6))\n") == "1:10: curveGAL's first argument must be a number from 1 to 5 (the view file names 5 curve file(s))");
    CHECK(errorWith("axiom: F(curveY(1))\n").find("curveY takes 2 arguments") != std::string::npos);
    auto curveError = [](const std::string& text) {
      return firstError([&] { CpfgCurve::parse(text, "c.con", 100); }, false);
    };
    CHECK(curveError("points: 4\n0 0\n1 1\n2 0\n") == "1:1: 'points: 4' but the file has 3 control point(s)");
    CHECK(curveError("points: 4\n0 0\n1 1\n2 0 5\n3 3\n") == "4:1: a control point has 2 numbers (the dimension), got 3");
    CHECK(curveError("points: 4\n0 0\n1 x\n2 0\n3 3\n") == "3:3: expected a number (a coordinate), got 'x'");
    CHECK(curveError("dimension: 3\npoints: 4\n") == "1:1: 'dimension:' must follow the 'points:' line");
    CHECK(curveError("points: 4\ntype: spiral\n") == "2:7: unknown curve type 'spiral' (bspline, bspline-closed, bspline-endpoint, bspline-phantom or bezier)");
    CHECK(curveError("points: 5\ntype: bezier\n0 0\n1 1\n2 0\n3 3\n4 4\n") == "1:1: a Bezier curve has 3k + 1 control points (counting multiplicities), got 5");
    CHECK(curveError("points: 4\ncolor: 3\n") == "2:1: unknown line in a curve file: 'color: 3'");
    CHECK(curveError("points: 4\n1 1\n1 1\n1 1\n1 1\n") == "1:1: the curve has length 0 (all its points coincide)");
    CHECK(curveError("points: 1\ndimension: 4\n0 0 0 2\npoints: 4\n") == "4:1: a second 'points:' line (cpfg's nested curves) is not supported");
  }
}

namespace {

// Contour samples from tests/assets/cpfg/contour/reference.py (cpfg's MakeContour in numpy).
const std::vector<DVec3> kBladeContour = {{0.897527467856, 0.000000000000, 0},  {0.330524728563, 0.891423755803, 0},
                                  {-0.650675635926, 1.100685813632, 0}, {-0.897527467856, 0.000000000000, 0},
                                  {-0.330524728563, -0.891423755803, 0}, {0.650675635926, -1.100685813632, 0},
                                  {0.897527467856, 0.000000000000, 0}};
const std::vector<DVec3> kStripContour = {{-0.500000000000, 0.283333341281, 0}, {-0.271197024029, 0.382473459469, 0},
                                  {-0.027807813170, 0.432723318993, 0}, {0.218184666413, 0.399404333018, 0},
                                  {0.450000000000, 0.307783341169, 0}};

/// A contour point k of a ring centred at c, drawn by the turtle at its start (H = +Y, L = -X,
/// cpfg's up U' = (0,0,-1)) with radius 0.2: c + 0.2 (k.x U' - k.y L).
DVec3 placedOnRing(const DVec3& c, const DVec3& k) { return c + DVec3(0.2 * k.y, 0, -0.2 * k.x); }

}  // namespace

TEST_CASE("cpfg contour files: samples and the rings of tests/assets/cpfg/contour", "[lsystem][cpfg]") {
  SECTION("contour files sampled as cpfg samples them") {
    const ViewFile view = loadViewFile(cpfgAsset("contour/plant.v"));
    REQUIRE(view.contours.size() == 2);
    CHECK(view.contourSides == 6);
    CHECK(view.contours[0].id == 1);
    CHECK(view.contours[0].contour.closed());
    CHECK(view.contours[0].contour.points().size() == 6);  // multiplicities 1, 2, 1, 2
    CHECK_FALSE(view.contours[1].contour.closed());
    const std::vector<DVec3> b = view.contours[0].contour.sample(6), s = view.contours[1].contour.sample(4);
    REQUIRE(b.size() == kBladeContour.size());
    REQUIRE(s.size() == kStripContour.size());
    for (size_t k = 0; k < b.size(); ++k) checkNear(b[k], kBladeContour[k]);
    for (size_t k = 0; k < s.size(); ++k) checkNear(s[k], kStripContour[k]);
  }
  SECTION("tests/assets/cpfg/contour: every ring point of the two cylinders") {
    // Turtle at the origin, H = +Y, L = -X, cpfg's up U' = (0,0,-1), radius 0.4 / 2: a
    // contour point (x, y) of a ring centred at c goes to c + 0.2 (x U' - y L) = c + (0.2y, 0, -0.2x).
    const Drawn o = drawObject("contour", true);
    CHECK(o.skeleton.internodes.empty());
    REQUIRE(o.skeleton.organs.size() == 2);
    const Organ& a = o.skeleton.organs[0];
    REQUIRE(a.points.size() == 14);
    REQUIRE(a.triangles.size() == 6 * 2 * 3);
    for (size_t m = 0; m < 7; ++m) {
      checkNear(a.points[m], placedOnRing(DVec3(0, 0, 0), kBladeContour[m]));
      checkNear(a.points[7 + m], placedOnRing(DVec3(0, 2, 0), kBladeContour[m]));
    }
    // The branch: @!(4) sides, strip at (0,2,0) blended into the circle at (0,3,0).
    const Organ& b = o.skeleton.organs[1];
    REQUIRE(b.points.size() == 10);
    const std::vector<DVec3> circle = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {1, 0, 0}};
    for (size_t m = 0; m < 5; ++m) {
      checkNear(b.points[m], placedOnRing(DVec3(0, 2, 0), kStripContour[m]));
      checkNear(b.points[5 + m], placedOnRing(DVec3(0, 3, 0), circle[m]));
    }
    // Every triangle's normal agrees with its vertices' normals.
    for (size_t k = 0; k < a.triangles.size(); k += 3) {
      const DVec3 n = glm::cross(a.points[a.triangles[k + 1]] - a.points[a.triangles[k]], a.points[a.triangles[k + 2]] - a.points[a.triangles[k]]);
      CHECK(glm::dot(n, a.normals[a.triangles[k]]) > 0);
    }
  }
}

TEST_CASE("cpfg generalized cylinders with @#(n): bent rings, F stays round, twist of cylinders", "[lsystem][cpfg]") {
  SECTION("a bent cylinder: a ring lies in the plane perpendicular to the curve's tangent") {
    // @Gt(0): zero tangents make the segment from (0,0,0) to (-1,1,0) (after f(1), + and
    // f(1)) the straight chord, its tangent along it; the middle ring (t = 1/2, of 2) is
    // centred at (-0.5, 0.5, 0) and perpendicular to the chord.
    ViewFile view = loadViewFile(cpfgAsset("contour/plant.v"));
    Grammar g = parseGrammar("axiom: @Gt(0) @#(1) @Gs f(1) + f(1) @Ge(2)\n", "t.l");
    Skeleton sk = Turtle(g.symbols(), cpfgTurtleSettings(&view, {})).run(g.axiom());
    REQUIRE(sk.organs.size() == 1);
    REQUIRE(sk.organs[0].points.size() == 3 * 7);
    const DVec3 dir = glm::normalize(DVec3(-1, 1, 0));
    for (size_t m = 0; m < 7; ++m) {
      const DVec3 p = sk.organs[0].points[7 + m] - DVec3(-0.5, 0.5, 0);
      CHECK(std::fabs(glm::dot(p, dir)) < 1e-9);
      CHECK(glm::length(p) == Approx(0.2 * glm::length(kBladeContour[m])));  // the contour point's radius, scaled
    }
  }
  SECTION("a contour does not shape an F: cpfg draws its cylinder round (irisGL.c, iGlEndCylNode)") {
    ViewFile view = loadViewFile(cpfgAsset("contour/plant.v"));
    Grammar with = parseGrammar("axiom: @#(1) @!(4) F(1) F(2)\n", "t.l"), without = parseGrammar("axiom: F(1) F(2)\n", "t.l");
    const Skeleton a = Turtle(with.symbols(), cpfgTurtleSettings(&view, {})).run(with.axiom());
    const Skeleton b = Turtle(without.symbols(), cpfgTurtleSettings(&view, {})).run(without.axiom());
    CHECK(a.organs.empty());
    REQUIRE(a.internodes.size() == 2);
    REQUIRE(b.internodes.size() == 2);
    for (size_t k = 0; k < 2; ++k) {
      checkNear(a.internodes[k].start, b.internodes[k].start);
      checkNear(a.internodes[k].end, b.internodes[k].end);
      CHECK(a.internodes[k].baseRadius == b.internodes[k].baseRadius);
      CHECK(a.internodes[k].baseRadius == Approx(0.2));  // initial line width 0.4: a round tube
    }
    CHECK(a.internodes[1].parent == 0);  // one axis, as without the contour
  }
  SECTION("twist of cylinders: a roll between control points turns the ring only when on") {
    // From (0,0,0) to (0,2,0) with a roll /(90) before the second point. Off (cpfg's
    // default): the second ring is the first one's frame carried along (adjust_up_and_leftS),
    // so both rings are the contour at U' = (0,0,-1), L = (-1,0,0): a point (x, y) at
    // c + 0.2 (x U' - y L) = c + (0.2y, 0, -0.2x). On: the second ring is the rolled
    // turtle's frame, U' and L turned 90 degrees about H = +Y: c + 0.2 (x, 0, y) (or its
    // mirror for the opposite roll), the middle ring half-way (45 degrees).
    auto rolled = [](const DVec3& c, const DVec3& k) { return c + DVec3(0.2 * k.x, 0, 0.2 * k.y); };
    for (const bool twist : {false, true}) {
      std::string text = readFile(cpfgAsset("contour/plant.v"));
      if (twist) text += "twist of cylinders: on\n";
      const ViewFile view = parseViewFile(text, cpfgAsset("contour/plant.v"));
      CHECK(view.twistCylinders == twist);
      Grammar g = parseGrammar("axiom: @Gt(0) @#(1) @Gs f(2) /(90) @Ge(2)\n", "t.l");
      const Skeleton sk = Turtle(g.symbols(), cpfgTurtleSettings(&view, {})).run(g.axiom());
      REQUIRE(sk.organs.size() == 1);
      const Organ& o = sk.organs[0];
      REQUIRE(o.points.size() == 3 * 7);
      for (size_t m = 0; m < 7; ++m) {
        checkNear(o.points[m], placedOnRing(DVec3(0, 0, 0), kBladeContour[m]));
        checkNear(o.points[14 + m],
                  twist ? rolled(DVec3(0, 2, 0), kBladeContour[m]) : placedOnRing(DVec3(0, 2, 0), kBladeContour[m]));
        // The middle ring at (0,1,0): untwisted, or turned by 45 degrees about +Y.
        const DVec3 a = placedOnRing(DVec3(0), kBladeContour[m]), r = rolled(DVec3(0), kBladeContour[m]);
        checkNear(o.points[7 + m], DVec3(0, 1, 0) + (twist ? (a + r) / std::sqrt(2.0) : a));
      }
    }
  }
}

TEST_CASE("cpfg contour errors: an unknown contour id, malformed contour files", "[lsystem][cpfg]") {
  SECTION("errors: an unknown contour id, malformed contour files") {
    ViewFile view = loadViewFile(cpfgAsset("contour/plant.v"));
    Grammar g = parseGrammar("axiom: @#(3) @Gs f(1) @Ge\n", "t.l");
    try {
      Turtle(g.symbols(), cpfgTurtleSettings(&view, {})).run(g.axiom());
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().message == "cpfg's '@#(3)' names no contour: the view file has no 'contour: 3 ...' line");
    }
    auto contourError = [](const std::string& text) {
      return firstError([&] { CpfgContour::parse(text, "c.con"); }, false);
    };
    CHECK(contourError("cver 2 0\n") == "1:6: contour file version 2.0 is not supported (cpfg reads 'cver 1 1' to 'cver 1 3' and the older 'n dim closed|open')");
    CHECK(contourError("cver 1 2\nname: x\npoints: 3 4\ntype: cr\n0 0 0 1\n1 0 0 1\n0 1 0 1\n") == "3:11: 'points: 3 4' but the multiplicities sum to 3");
    CHECK(contourError("cver 1 2\nname: x\npoints: 3 3\ntype: xr\n") == "4:7: a contour's type is 'o' (open) or 'c' (closed) then 'r' (regular) or 'e', got 'xr'");
    CHECK(contourError("4 2 open\n0 0\n1 1\n2 0\n") == "4:1: the contour file ends before point 4 of its 4");
    CHECK(contourError("3 2 open\n0 0\n1 1\n2 0\n") == "1:1: an open contour needs at least 4 points (counting multiplicities), got 3");
    CHECK(contourError("3 2 closed\n0 0\n1 one\n2 0\n") == "3:3: expected a number (a coordinate), got 'one'");
    CHECK(viewErrorOf("contour: 0 a.con\n") == "t.v:1:10: contour id 0 is cpfg's circle; a contour file takes another id");
    CHECK(viewErrorOf("contour sides: 2\n") == "t.v:1:16: 'contour sides:' is a whole number from 3 to 1024");
  }
}

TEST_CASE("cpfg generalized cylinders: @Gr radius tangents", "[lsystem][cpfg]") {
  // general.c, interpolate_connection: the rings are the Hermite cubic of the pairs
  // (t, radius) from (0, r1) to (1, r2) with the radius tangents. @Gr(90, 1) makes both
  // (0, 1): with r1 = r2 = 0.2, ring k of 4 (r = k/4) is at t = 3r^2 - 2r^3 with radius
  // 0.2 + r - 3r^2 + 2r^3; @Gt(0) makes the curve p1 + (3t^2 - 2t^3)(p2 - p1).
  ViewFile view = parseViewFile("initial line width: 0.4\nline style: cylinder\n", "t.v");
  auto expect = [](const Skeleton& sk, double length) {
    REQUIRE(sk.internodes.size() == 4);
    auto at = [&](int k) {
      const double r = k / 4.0, t = 3 * r * r - 2 * r * r * r;
      return std::pair{DVec3(0, length * (3 * t * t - 2 * t * t * t), 0), 0.2 + r - 3 * r * r + 2 * r * r * r};
    };
    for (int k = 1; k <= 4; ++k) {
      INFO("ring " << k);
      checkNear(sk.internodes[static_cast<size_t>(k - 1)].start, at(k - 1).first);
      checkNear(sk.internodes[static_cast<size_t>(k - 1)].end, at(k).first);
      CHECK(sk.internodes[static_cast<size_t>(k - 1)].baseRadius == Approx(at(k - 1).second).margin(1e-12));
      CHECK(sk.internodes[static_cast<size_t>(k - 1)].tipRadius == Approx(at(k).second).margin(1e-12));
    }
  };
  Grammar g = parseGrammar("axiom: @Gt(0) @Gr(90, 1) @Gs f(1) @Ge(4)\n", "t.l");
  expect(Turtle(g.symbols(), cpfgTurtleSettings(&view, {})).run(g.axiom()), 1.0);
  // @Gr(1): tangents times the segment's length, so (0, 0.5) on a segment of 2 is (0, 1).
  Grammar s = parseGrammar("axiom: @Gt(0) @Gr(1) @Gr(90, 0.5) @Gs f(2) @Ge(4)\n", "t.l");
  expect(Turtle(s.symbols(), cpfgTurtleSettings(&view, {})).run(s.axiom()), 2.0);
  // The middle ring of the first: r = 1/2 gives t = 1/2 and radius 0.2 (the curve's middle).
  Grammar m = parseGrammar("axiom: @Gt(0) @Gr(90, 1) @Gs f(1) @Ge(2)\n", "t.l");
  Skeleton mid = Turtle(m.symbols(), cpfgTurtleSettings(&view, {})).run(m.axiom());
  REQUIRE(mid.internodes.size() == 2);
  checkNear(mid.internodes[0].end, DVec3(0, 0.5, 0));
  CHECK(mid.internodes[0].tipRadius == Approx(0.2));
}

TEST_CASE("cpfg view files: // comments", "[lsystem][cpfg]") {
  // cpfg runs the view file through the C preprocessor, which removes // and /* */ comments
  // (vlab's TexturedSurfaces has '// light: ...' lines).
  const ViewFile v = parseViewFile("angle increment: 30 // degrees\n// light: V: 5 3 1 D: 1.3 1.5 1.3\n/* a\n b */ initial scale: 2\n", "t.v");
  REQUIRE(v.angleDeg);
  CHECK(*v.angleDeg == 30);
  REQUIRE(v.initialScale);
  CHECK(*v.initialScale == 2);
  CHECK(viewErrorOf("// fine\nangel increment: 3\n") == "t.v:2:1: unknown view file command 'angel increment:' (did you mean 'angle increment'?)");
}

TEST_CASE("cpfg function sets: function set: and the functions' names", "[lsystem][cpfg]") {
  const ViewFile view = loadViewFile(cpfgAsset("function_set/plant.v"));
  REQUIRE(view.functions.size() == 2);  // the set replaces the 'function:' line before it
  CHECK(view.functionNames == std::vector<std::string>{"WIDTH", "ANGLE"});
  GrammarOverrides o;
  o.cpfgFunctions = view.functions;
  o.cpfgFunctionNames = view.functionNames;
  const std::string file = cpfgAsset("function_set/plant.l");
  const ModuleString s = derive(parseGrammar(readFile(file), file, o));
  REQUIRE(s.size() == 1);
  const std::vector<double> want = {0.15625, 0.783014893532, 0.066938758886};  // tests/assets/cpfg/function/reference.py
  REQUIRE(s.paramsOf(0).size() == 3);
  for (size_t k = 0; k < 3; ++k) CHECK(s.paramsOf(0)[k] == Approx(want[k]).margin(1e-9));
  // A 'function:' line after the set: the names are no longer defined (cpfg's
  // SetFunctionsFromGallery(FALSE)).
  std::string v2 = readFile(cpfgAsset("function_set/plant.v")) + "function: ignored.func\n";
  const std::string dir = cpfgAsset("function_set/");
  const ViewFile after = parseViewFile(v2, dir + "plant.v");
  CHECK(after.functions.size() == 3);
  CHECK(after.functionNames.empty());
  CHECK(viewErrorOf("function set: a.fset b\n") == "t.v:1:15: expected one function set file after 'function set:'");
}

TEST_CASE("cpfg define: arrays", "[lsystem][cpfg]") {
  // Row-major flat initializers as cpfg reads them; blank lines inside the open block.
  const std::string g =
      "#define N 3\n"
      "define: {\n"
      "\tarray w[N] = {1, 2.5, 4};\n"
      "\n"
      "\tarray m[2][N] =\n"
      "\t\t{1, 2, 3,\n"
      "\t\t 4, 5, 6};\n"
      "\tarray z[4];\n"
      "}\n"
      "Start: { z[1] = m[1][2] + w[0]; }\n"
      "axiom: A(0)\n"
      "A(i) : i < N { k = w[i]; z[2] = z[2] + 1; } --> F(k) B(m[1][i], z[1], z[2]) A(i+1)\n";
  SECTION("reads, stores in Start: and in a production's block") {
    // Step 1: A(0): k = w[0] = 1, z[2] = 1; m[1][0] = 4; z[1] = m[1][2] + w[0] = 6 + 1 = 7.
    // Step 2: A(1): k = 2.5, z[2] = 2, m[1][1] = 5. Step 3: A(2): k = 4, z[2] = 3, m[1][2] = 6.
    CHECK(derived(g, 2) == "F(1)B(4,7,1)F(2.5)B(5,7,2)A(2)");
    CHECK(derived(g, 4) == "F(1)B(4,7,1)F(2.5)B(5,7,2)F(4)B(6,7,3)A(3)");  // A(3): i < N fails, nothing runs
  }
  SECTION("missing values are 0; nested braces read as one flat list; the axiom reads initial values") {
    CHECK(derived("define: { array a[2][2] = {{1, 2}, {3}}; }\naxiom: X(a[0][1], a[1][0], a[1][1])\n", 0) == "X(2,3,0)");
    CHECK(derived("define: { array a[3] = {5, 6}; }\naxiom: A\nA --> X(a[2] + a[1], a[1.9])\n", 1) == "X(6,6)");
  }
  SECTION("an index out of range at run time names the array and the index") {
    CHECK_THROWS_WITH(derived("define: { array a[3]; }\naxiom: A(3)\nA(i) --> X(a[i])\n", 1),
                      Catch::Matchers::Contains("index 3 of cpfg's array 'a' is out of range (it is a[3], indices 0 to 2)"));
    CHECK_THROWS_WITH(derived("define: { array a[2][3]; }\naxiom: A(-1)\nA(i) --> X(a[1][i])\n", 1),
                      Catch::Matchers::Contains("index -1 in its dimension 2 of cpfg's array 'a' is out of range"));
  }
  SECTION("errors") {
    CHECK(errorOf("define: { array a[2]; }\naxiom: X(a[2])\n") ==
          "t.l:2:11: index 2 of cpfg's array 'a' is out of range (indices 0 to 1)");
    CHECK(errorOf("define: { array a[2][2]; }\naxiom: X(a[1])\n") == "t.l:2:14: cpfg's array 'a' takes 2 indices, got 1");
    CHECK(errorOf("define: { array a[2] = {1, 2, 3}; }\naxiom: A\n") ==
          "t.l:1:31: too many values for the array 'a' (it has 2 elements)");
    CHECK(errorOf("define: { array a[0]; }\naxiom: A\n") ==
          "t.l:1:19: an array's size must be a whole number of at least 1, got 0");
    CHECK(errorOf("define: { int a[2]; }\naxiom: A\n") ==
          "t.l:1:11: expected 'array name[size] = {...};' in 'define:' (cpfg's define block declares arrays)");
    CHECK(errorOf("define: { array a; }\naxiom: A\n") == "t.l:1:18: expected '[size]' after the array's name 'a'");
    CHECK(errorOf("define: { array a[2]; }\nStart: { a = 1; }\naxiom: A\n") ==
          "t.l:2:10: cannot assign to 'a': it is an array (assign its elements, 'a[i] = ...')");
  }
}

TEST_CASE("cpfg's #if", "[lsystem][cpfg]") {
  auto axiomOf = [](const std::string& text) {
    const Grammar g = parseGrammar(text, "t.l");
    return formatModuleString(g.axiom(), g.symbols());
  };
  // vlab's clover and two-trees objects: `#if LEAVES==1` over a #define constant
  CHECK(axiomOf("#define LEAVES 1\n#if LEAVES==1\naxiom: A\n#else\naxiom: B\n#endif\n") == "A");
  CHECK(axiomOf("#define LEAVES 2\n#if LEAVES==1\naxiom: A\n#else\naxiom: B\n#endif\n") == "B");
  CHECK(axiomOf("#define N (2)\n#if N > 1 && !(N >= 3) || 0\naxiom: A\n#else\naxiom: B\n#endif\n") == "A");
  CHECK(axiomOf("#if UNDEFINED\naxiom: A\n#else\naxiom: B\n#endif\n") == "B");  // an unknown name is 0, as in C
  CHECK(axiomOf("#define K 3\n#if defined(K) && defined K && !defined(L) && K % 2 == 1 && -K < 0\naxiom: A\n#else\naxiom: B\n#endif\n") == "A");
  CHECK(axiomOf("#if 0\n#if 1 +\n#endif\naxiom: B\n#else\naxiom: A\n#endif\n") == "A");  // not evaluated inside a false block
}
