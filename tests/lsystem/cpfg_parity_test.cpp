// Parity with vlab's cpfg: the objects under tests/assets/cpfg/parity/, each derived by Sprig
// and compared module by module with the string the real cpfg derived from it (cpfg.str,
// made by the command in that folder's README).

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "lsystem/view_file.h"
#include "tests/lsystem/cpfg_compare.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

std::string parityAsset(const std::string& name) {
  return std::string(SPRIG_SOURCE_DIR) + "/tests/assets/cpfg/parity/" + name;
}

std::string cpfgString(const std::string& folder) { return test::readCpfgString(parityAsset(folder + "/cpfg.str")); }

/// A parity object: its grammar (with its view file's turtle for the query modules, when it
/// has one), derived to its own length.
struct Parity {
  Grammar grammar;
  std::optional<TurtleSettings> turtle;
  bool box = false;  ///< the view file has a `box:` line
};

Parity loadParity(const std::string& folder) {
  Parity p;
  p.grammar = loadGrammar(parityAsset(folder + "/plant.l"));
  REQUIRE(p.grammar.cpfgNotation());
  const std::string v = parityAsset(folder + "/plant.v");
  if (std::filesystem::exists(v)) {
    const ViewFile view = loadViewFile(v);
    p.turtle = cpfgTurtleSettings(&view, TurtleSettings{});
    p.box = view.box;
  } else {
    p.turtle = cpfgTurtleSettings(nullptr, TurtleSettings{});
  }
  return p;
}

void checkSame(const ModuleString& got, const SymbolTable& symbols, const std::string& cpfg) {
  test::checkSameAsCpfg(got, symbols, cpfg);
}

ModuleString deriveParity(Parity& p) {
  DeriveOptions opt;
  opt.queryTurtle = p.turtle;
  opt.queriesAfterLastStep = !p.box;
  Deriver d(p.grammar, opt);
  return d.derive();
}

/// Derives the fixture in folder and compares it with the real cpfg's string kept there.
void checkParity(const std::string& folder) {
  Parity p = loadParity(folder);
  checkSame(deriveParity(p), p.grammar.symbols(), cpfgString(folder));
}

}  // namespace

TEST_CASE("cpfg parity: '=' and ']' in right contexts", "[lsystem][cpfg]") {
  Parity p = loadParity("skip_branch");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("skip_branch"));
  SECTION("the same grammar in Sprig's notation keeps lpfg's ']' and '=' as a module") {
    std::string text = readFile(parityAsset("skip_branch/plant.l"));
    Grammar g = parseGrammar(text, "plant.lsys");
    Deriver d(g);
    // lpfg: X > [B]C matches X[BD]C (']' skips the rest of the branch); '=' is a symbol no
    // module of the string is, so I, E and S stay.
    CHECK(formatModuleString(d.derive(), d.symbols()) == "I(1)[+I(2)F][I(3)FF]I(4)Q[BD]CR[B]C[EFH]GS[+T]");
  }
  SECTION("'=' takes no parameters") {
    try {
      parseGrammar("axiom: A\nA > [B=(1)] --> C\n", "t.l");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("t.l:2:7: error: cpfg's '=' in a right context (skip the rest of the branch) takes no "
                                       "parameters") != std::string::npos);
    }
  }
}

TEST_CASE("cpfg parity: parameters are floats, expressions doubles", "[lsystem][cpfg]") {
  Parity p = loadParity("float_params");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("float_params"));
  // A's age after 100 steps of 0.02 is the float 1.99999, so it has not fired after 101.
  CHECK(countSymbol(s, p.grammar.symbols(), "F") == 0);
  SECTION("printed as floats") {
    // 2.0199988 is the float cpfg's %g prints as 2.02
    CHECK(formatModuleString(s, p.grammar.symbols(), FormatOptions{0, true}).substr(0, 13) == "A(2.0199988)B");
  }
  SECTION("Sprig's notation keeps doubles: the age reaches 2 and fires") {
    Grammar g = parseGrammar(readFile(parityAsset("float_params/plant.l")), "plant.lsys");
    Deriver d(g);
    CHECK(countSymbol(d.derive(), d.symbols(), "F") == 1);
  }
}

TEST_CASE("cpfg parity: query modules of the final string", "[lsystem][cpfg]") {
  // cpfg fills query modules whenever it interprets the string: before each step and when it
  // draws the result, so the final string holds the drawn turtle's values (cpfg -g leaves
  // them as they were only when the view file's 'box:' spares it the drawing).
  checkParity("query_timing");
}

TEST_CASE("cpfg parity: a view file's box: leaves the final string's query modules unfilled", "[lsystem][cpfg]") {
  Parity p = loadParity("query_box");
  REQUIRE(p.box);
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("query_box"));
  SECTION("a further step fills them first, as cpfg's next step does") {
    DeriveOptions opt;
    opt.queryTurtle = p.turtle;
    opt.queriesAfterLastStep = false;
    Deriver d(p.grammar, opt);
    d.derive();
    const ModuleString& more = d.step();
    // B records ?P's y when step 4 started: 3 (three F(1) below it), not the 2 it held.
    const std::string text = formatModuleString(more, d.symbols());
    CHECK(text.find("B(2)B(3)?P(0,3,0)") != std::string::npos);
  }
  SECTION("without box: the final string is filled, as cpfg's drawing fills it") {
    DeriveOptions opt;
    opt.queryTurtle = p.turtle;
    Deriver d(p.grammar, opt);
    CHECK(formatModuleString(d.derive(), d.symbols()).find("B(2)?P(0,3,0)") != std::string::npos);
  }
}

TEST_CASE("cpfg parity: a cut is made when the next step reaches it", "[lsystem][cpfg]") {
  for (const char* folder : {"pending_cut", "decomposition_cut"}) {
    INFO(folder);
    checkParity(folder);
  }
  SECTION("drawn, the pending cut is skipped and marks nothing: the skeleton of the string cut") {
    Parity p = loadParity("pending_cut");
    const ModuleString s = deriveParity(p);
    SymbolTable table = p.grammar.symbols();
    const ModuleString cut = parseModuleString("X[F(1)]F(2)[F(1)]F(2)[A]BE", table);
    REQUIRE(table.size() == p.grammar.symbols().size());
    Turtle t(p.grammar.symbols(), *p.turtle);
    const Skeleton a = t.run(s), b = t.run(cut);
    REQUIRE(a.internodes.size() == 4);
    REQUIRE(a.internodes.size() == b.internodes.size());
    for (size_t i = 0; i < a.internodes.size(); ++i) {
      CHECK(glm::length(a.internodes[i].start - b.internodes[i].start) < 1e-12);
      CHECK(glm::length(a.internodes[i].end - b.internodes[i].end) < 1e-12);
      CHECK(a.internodes[i].parent == b.internodes[i].parent);
      CHECK(!a.internodes[i].cut);
    }
  }
  SECTION("Sprig's notation cuts at once, keeping the % that marks the cut internode") {
    Grammar g = parseGrammar(readFile(parityAsset("pending_cut/plant.l")), "plant.lsys");
    Deriver d(g);
    CHECK(formatModuleString(d.derive(), d.symbols()) == "X[F(1)%]F(2)[F(1)%]F(2)[A]BE");
  }
}

TEST_CASE("cpfg parity: a production for a command's last letter rewrites the command", "[lsystem][cpfg]") {
  checkParity("split_command");
}

TEST_CASE("cpfg parity: a rule for a letter of a command the grammar writes is an error", "[lsystem][cpfg]") {
  auto errorOf = [](const std::string& text) -> std::string {
    try {
      parseGrammar(text, "t.l");
    } catch (const InputError& e) {
      return e.what();
    }
    return "no error";
  };
  // cpfg's string holds '@' then 'o(0.2)': its o(r) rule grows the sphere (vlab's Mycelis,
  // supported: split_command); a successor that does not start with 'o' again is not.
  CHECK(errorOf("axiom: A@o(0.2)\no(r) --> o(r+0.03)\n") == "no error");
  CHECK(errorOf("axiom: A@o(0.2)\no(r) --> F o(r+0.03)\n").find(
            "t.l:2:1: error: cpfg reads '@o' as the modules '@', 'o' (one character each), so this rule's 'o' also matches "
            "the 'o' of the '@o' the grammar writes; Sprig reads '@o' as one module: not supported (rename the module 'o')") !=
        std::string::npos);
  CHECK(errorOf("axiom: A?P(0,0)\nA > P(x,y) --> B\n").find("cpfg reads '?P' as the modules '?', 'P'") != std::string::npos);
  CHECK(errorOf("axiom: A@Ts(1,2)\nT --> B\n").find("cpfg reads '@Ts' as the modules '@', 'T', 's'") != std::string::npos);
  // The letter's parameters differ from the command's: no cpfg module matches, no error.
  CHECK(errorOf("axiom: A@o(0.2)@Ts(1,2)\ns --> A\no --> A\nT(x) --> A\n") == "no error");
}

#if defined(__unix__) || defined(__APPLE__)
TEST_CASE("Rand48 draws the POSIX rand48 sequence (libc's erand48 and drand48)", "[lsystem][cpfg]") {
  // libc is the oracle: the same states, the same doubles, bit for bit.
  unsigned short x[3] = {0x330E, 0x1234, 0xABCD};
  Rand48 r = Rand48::fromWords(0x330E, 0x1234, 0xABCD);
  for (int i = 0; i < 2000; ++i) {
    const double want = erand48(x);
    REQUIRE(r.next() == want);
    REQUIRE(r.state() == (uint64_t{x[0]} | uint64_t{x[1]} << 16 | uint64_t{x[2]} << 32));
  }
  unsigned short seed[3] = {7, 0, 155};
  seed48(seed);
  Rand48 d = Rand48::fromWords(7, 0, 155);
  for (int i = 0; i < 2000; ++i) REQUIRE(d.next() == drand48());
  // State 0 (drand48 never seeded, as cpfg -g draws): the first draw is 11 / 2^48.
  Rand48 z;
  CHECK(z.next() == 11.0 / 281474976710656.0);
}
#endif

TEST_CASE("cpfg parity: cpfg's random sequences", "[lsystem][cpfg]") {
  // stochastic: one drand48 draw for every module a step visits (those with no production
  // too), chosen among every applicable production, in float; unseeded: 'seed: 0' draws
  // the same (cpfg -g never seeds drand48, whatever the seed); random_functions: ran, nran
  // (the first returns the mean), bran, biran from one erand48 stream, reseeded by srand in
  // a production.
  // interpretation_draws: interpretation rules draw depth first, after an srand in one of
  // them (the query module holds the drawn length: 13.2645).
  for (const char* folder : {"stochastic", "unseeded", "random_functions", "interpretation_draws"}) {
    INFO(folder);
    checkParity(folder);
  }
  SECTION("the same string at 1 and 2 threads") {
    for (const char* folder : {"stochastic", "random_functions"}) {
      Parity p = loadParity(folder);
      std::string one, two;
      {
        ThreadLimit limit(1);
        one = formatModuleString(deriveParity(p), p.grammar.symbols());
      }
      {
        ThreadLimit limit(2);
        two = formatModuleString(deriveParity(p), p.grammar.symbols());
      }
      CHECK(one == two);
    }
  }
  SECTION("a seed given to Sprig seeds drand48 as cpfg's window does: another string") {
    Grammar g = loadGrammar(parityAsset("stochastic/plant.l"));
    DeriveOptions opt;
    opt.seed = 7;
    Deriver d(g, opt);
    CHECK(formatModuleString(d.derive(), d.symbols(), FormatOptions{0, true}) !=
          formatModuleString(derive(g), g.symbols(), FormatOptions{0, true}));
  }
  SECTION("without 'seed:' cpfg applies the first applicable production, whatever its weight") {
    Grammar g = parseGrammar("derivation length: 3\naxiom: A\nA --> AB : 1\nA --> C : 5\n", "t.l");
    CHECK(formatModuleString(derive(g), g.symbols()) == "ABBB");
  }
}

TEST_CASE("cpfg parity: local variables keep their values between applications", "[lsystem][cpfg]") {
  // A(0) keeps the k of the A before it, j counts every application of B's production over
  // the steps, and D(i) follows from C's loop.
  Parity p = loadParity("local_variables");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("local_variables"));
  CHECK(formatModuleString(s, p.grammar.symbols()) == "D(35)D(35)D(21)D(21)");
  SECTION("Sprig's notation starts them at 0 every time") {
    Grammar g = parseGrammar("derivation length: 1\naxiom: A(3)A(0)\nA(n) : { if (n > 0) { k = n * 10; } } * --> B(k)\n", "t.lsys");
    CHECK(formatModuleString(derive(g), g.symbols()) == "B(30)B(0)");
  }
}

TEST_CASE("cpfg parity: a '\\\\' line continuation leaves a '\\' cpfg's expressions pass over", "[lsystem][cpfg]") {
  Parity p = loadParity("line_continuation");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("line_continuation"));
  // len(x) = 2x + 1 over x = 1, 2, 3.
  CHECK(formatModuleString(s, p.grammar.symbols()) == "F(3)F(5)F(7)A(4)");
  SECTION("Sprig's own notation still refuses it") {
    CHECK_THROWS_WITH(parseGrammar("axiom: F\nA(x) --> B(x \\ 2)\n", "g.lsys"),
                      Catch::Contains("g.lsys:2:14: error: unexpected character '\\' in expression"));
  }
}

TEST_CASE("cpfg parity: 'angle increment: ?' keeps the angle in effect", "[lsystem][cpfg]") {
  Parity p = loadParity("view_angle_query");
  const ModuleString s = deriveParity(p);
  // The query modules stand at 30 and 60 degrees from the vertical: the first line's 30.
  checkSame(s, p.grammar.symbols(), cpfgString("view_angle_query"));
  const ViewFile v = loadViewFile(parityAsset("view_angle_query/plant.v"));
  REQUIRE(v.angleDeg);
  CHECK(*v.angleDeg == 30.0);
  REQUIRE(v.warnings.size() == 1);
  CHECK(v.warnings[0].loc.line == 2);
  CHECK(v.warnings[0].message.find("'angle increment: ?' has no number") != std::string::npos);
  SECTION("alone it leaves cpfg's default; 'angle factor: ?' divides 360 by the angle in effect") {
    CHECK_FALSE(parseViewFile("angle increment: ?\n", "t.v").angleDeg);
    CHECK(parseViewFile("angle factor: ?\n", "t.v").angleDeg == 8.0);
    CHECK(parseViewFile("angle increment: 10\nangle factor: ?\n", "t.v").angleDeg == 36.0);
  }
}

TEST_CASE("cpfg parity: blanks between '@' and its letters", "[lsystem][cpfg]") {
  Parity p = loadParity("at_blank");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("at_blank"));
  CHECK(countSymbol(s, p.grammar.symbols(), "@c") == 4);
  SECTION("a lone '@' is still refused") {
    CHECK_THROWS_WITH(parseGrammar("axiom: F@ +F\n", "t.l"), Catch::Contains("t.l:1:9: error: unknown cpfg command '@'"));
  }
}

TEST_CASE("cpfg parity: a texture image that cannot be read does not stop a derivation", "[lsystem][cpfg]") {
  Parity p = loadParity("texture_unread");
  const ModuleString s = deriveParity(p);
  // Whole numbers only: the text compares ('@Tx' is refused by Sprig's string reader).
  CHECK(formatModuleString(s, p.grammar.symbols()) == cpfgString("texture_unread"));
  const ViewFile v = loadViewFile(parityAsset("texture_unread/plant.v"));
  REQUIRE(v.textures.size() == 1);
  CHECK_FALSE(v.textures[0].image);
  REQUIRE(v.textures[0].unreadable);
  CHECK(v.textures[0].unreadable->loc.line == 1);
  CHECK(v.textures[0].unreadable->loc.col == 13);
}

TEST_CASE("cpfg parity: '?' without parameters is a module; its turtle takes the next one", "[lsystem][cpfg]") {
  Parity p = loadParity("bare_query");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("bare_query"));
  // ????F(1)??F(2)F(1)?F(2)A: each '?' takes the module after it, so F(1), F(2) and F(1)
  // are drawn (3 internodes, length 4) and the last F(2) is not.
  Turtle t(p.grammar.symbols(), *p.turtle);
  const Skeleton k = t.run(s);
  REQUIRE(k.internodes.size() == 3);
  CHECK(k.totalLength() == Approx(4.0).margin(1e-12));
  SECTION("a '?' before a query letter, a bracket or a command is an error, not a different drawing") {
    SymbolTable table = p.grammar.symbols();
    for (const char* text : {"?P(1,2)F", "?[F]", "?@v"}) {
      INFO(text);
      const ModuleString q = parseModuleString(text, table, "t.l");
      Turtle tq(table, *p.turtle);
      if (std::string(text) == "?P(1,2)F") {
        CHECK(tq.run(q).internodes.size() == 1);  // '?P' is one module: a query
      } else {
        CHECK_THROWS_WITH(tq.run(q), Catch::Contains("cpfg's '?' followed by the module"));
      }
    }
  }
}

TEST_CASE("cpfg parity: productions assign global variables, left to right", "[lsystem][cpfg]") {
  checkParity("global_assign");
}

TEST_CASE("cpfg parity: brackets in the ignore table", "[lsystem][cpfg]") {
  for (const char* folder : {"ignored_brackets", "considered_brackets"}) {
    INFO(folder);
    checkParity(folder);
  }
}

TEST_CASE("cpfg parity: a predecessor may hold brackets, matched module by module", "[lsystem][cpfg]") {
  checkParity("bracket_predecessor");
  SECTION("Sprig's notation keeps brackets out of predecessors") {
    CHECK_THROWS_WITH(parseGrammar("axiom: A[B]\n[B] --> C\n", "g.lsys"),
                      Catch::Contains("g.lsys:2:1: error: a bracket cannot be a predecessor"));
  }
}

TEST_CASE("cpfg parity: the interpretation rule '@G' rewrites every generalized-cylinder command", "[lsystem][cpfg]") {
  checkParity("gencyl_prefix");
  SECTION("interpreted: each command is replaced, in the rule's place among the rules for '@'") {
    auto interpreted = [](const std::string& rules) {
      Grammar g = parseGrammar("axiom: F@GsF(1)@Gc(2)F@Ge(3)@Gt(1,2)@Ge\nhomomorphism\n" + rules, "t.l");
      Deriver d(g);
      return formatModuleString(d.interpret(d.derive()), d.symbols());
    };
    CHECK(interpreted("@G --> *\n") == "FF(1)F");
    CHECK(interpreted("@Gc(n) --> f(n)\n@G --> *\n") == "FF(1)f(2)F");
    CHECK(interpreted("@G --> *\n@Gc(n) --> f(n)\n") == "FF(1)F");
  }
  SECTION("only in interpretation rules") {
    CHECK_THROWS_WITH(parseGrammar("axiom: @GsF@Ge\n@G --> *\n", "t.l"),
                      Catch::Contains("t.l:2:1: error: cpfg's predecessor '@G' (the '@' and 'G' of the generalized-cylinder "
                                      "commands) is supported only in an interpretation (homomorphism) rule"));
  }
}

TEST_CASE("cpfg parity: fopen, fprintf, fflush and fclose in the Start/EachStep/End blocks", "[lsystem][cpfg]") {
  // The grammar is copied to a scratch folder: its files are written beside it.
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sprig-cpfg-files-test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::filesystem::copy_file(parityAsset("files/plant.l"), dir / "plant.l");
  Grammar g = loadGrammar((dir / "plant.l").string());
  {
    Deriver d(g);
    checkSame(d.derive(), g.symbols(), cpfgString("files"));
  }
  // What the real cpfg wrote: "w" truncates, "a" appends, indices 24 and 23, %.lf and %%.
  CHECK(readFile((dir / "out.txt").string()) == readFile(parityAsset("files/out.txt")));
  CHECK(readFile((dir / "log.txt").string()) == readFile(parityAsset("files/log.txt")));
  {
    Deriver d(g);  // a second derivation: out.txt written again, log.txt appended to
    d.derive();
  }
  CHECK(readFile((dir / "out.txt").string()) == readFile(parityAsset("files/out.txt")));
  CHECK(readFile((dir / "log.txt").string()) == "start 24 23\nstart 24 23\n");
  SECTION("the named errors outside the subset") {
    auto errorOf = [](const std::string& text) {
      try {
        parseGrammar(text, "t.l");
      } catch (const std::exception& e) {
        return std::string(e.what());
      }
      return std::string();
    };
    CHECK_THAT(errorOf("axiom: A\nA : * {f = fopen(\"x.txt\", \"w\");} --> B\n"),
               Catch::Contains("t.l:2:12: error: cpfg's function 'fopen' is supported only in the Start:, StartEach:, "
                               "EndEach: and End: blocks of a .l file"));
    CHECK_THAT(errorOf("Start: {f = fopen(\"../x.txt\", \"w\");}\naxiom: A\n"),
               Catch::Contains("t.l:1:19: error: fopen's file '../x.txt' must be a plain file name: Sprig writes only in "
                               "the grammar's folder"));
    CHECK_THAT(errorOf("Start: {f = fopen(\"x.txt\", \"r\");}\naxiom: A\n"),
               Catch::Contains("t.l:1:28: error: cpfg's fopen mode 'r' is not supported"));
    CHECK_THAT(errorOf("Start: {f = 1 + fopen(\"x.txt\", \"w\");}\naxiom: A\n"),
               Catch::Contains("cpfg's function 'fopen' (file input and output) is not supported"));
    CHECK_THAT(errorOf("Start: {f = 0; n = fscanf(f, \"%f\", x);}\naxiom: A\n"),
               Catch::Contains("cpfg's function 'fscanf' (file input) is not supported"));
    CHECK_THAT(errorOf("Start: {f = 0;}\nEnd: {fprintf(f, \"%g %g\", 1);}\naxiom: A\n"),
               Catch::Contains("fprintf's format has 2 conversion(s) for 1 value(s)"));
  }
}

TEST_CASE("cpfg parity: '@Tx(n)' naming no texture does not stop the query modules", "[lsystem][cpfg]") {
  checkParity("texture_query");
}

TEST_CASE("cpfg parity: the turtle interprets past a '%' awaiting its cut", "[lsystem][cpfg]") {
  checkParity("query_past_cut");
}

TEST_CASE("cpfg's '%' with parameters (a cut branch moved for an environmental program) is an error", "[lsystem][cpfg]") {
  // cpfg's %(n) and %(n, t) (interpret.c, generate.c: cut_substrings) work only with an
  // environmental program; Sprig names them rather than cut or skip nothing.
  CHECK_THROWS_WITH(parseGrammar("axiom: A[F%(1)F]F\n", "t.l"),
                    Catch::Contains("t.l:1:11: error: cpfg's '%(n)' (a cut whose branch cpfg moves to the end of the string"));
  CHECK_THROWS_WITH(parseGrammar("axiom: A\nA --> [F%(0, 1)F]\n", "t.l"),
                    Catch::Contains("t.l:2:9: error: cpfg's '%(n, t)' (a moved cut branch, drawn from the turtle saved for it)"));
  SECTION("a string built without the parser: the turtle refuses it too") {
    Grammar g = parseGrammar("axiom: F%F\n", "t.l");
    ModuleString s;
    const SymbolId f = static_cast<SymbolId>(g.symbols().find("F")), cut = static_cast<SymbolId>(g.symbols().find("%"));
    const double one[] = {1.0}, two[] = {1.0, 0.0};
    s.push(f, one);
    s.push(cut, one);
    s.push(f, one);
    Turtle t(g.symbols(), cpfgTurtleSettings(nullptr, {}));
    CHECK_THROWS_WITH(t.run(s), "sprig: error: cpfg's '%(n)' (a cut whose branch cpfg moves to the end of the string, with the turtle saved for it) is not supported");
    ModuleString s2;
    s2.push(cut, two);
    CHECK_THROWS_WITH(t.run(s2), Catch::Contains("cpfg's '%(n, t)'"));
  }
}

TEST_CASE("cpfg parity: an expression statement is evaluated and dropped", "[lsystem][cpfg]") {
  checkParity("expression_statement");
}

TEST_CASE("cpfg parity: '_' is a command, written with any parameter count", "[lsystem][cpfg]") {
  checkParity("elasticity_module");
}

TEST_CASE("cpfg parity: the axiom reads the globals the Start: block set", "[lsystem][cpfg]") {
  checkParity("axiom_globals");
}

TEST_CASE("cpfg parity: a ring L-system joins the ends of the string", "[lsystem][cpfg]") {
  Parity p = loadParity("ring");
  checkSame(deriveParity(p), p.grammar.symbols(), cpfgString("ring"));
  SECTION("without 'ring lsystem' the ends are not joined") {
    std::string text = readFile(parityAsset("ring/plant.l"));
    text.replace(text.find("ring lsystem"), 12, "");
    Grammar g = parseGrammar(text, "plant.l");
    Deriver d(g, DeriveOptions{.steps = 1});
    // The first B has no left neighbour: it stays; A(1) still becomes B(1).
    CHECK(formatModuleString(d.derive(), d.symbols()) == "B(0)B(0)[F]B(10)B(1)+");
  }
  SECTION("only the main L-system of a .l file") {
    CHECK_THROWS_WITH(parseGrammar("ring lsystem\naxiom: A\n", "t.lsys"),
                      Catch::Contains("t.lsys:1:1: error: cpfg's 'ring lsystem' (ring L-system) is supported only for the "
                                      "main L-system of a .l file"));
  }
}

TEST_CASE("cpfg parity: @L labels in interpretation rules are read and drawn as text at the turtle", "[lsystem][cpfg]") {
  Parity p = loadParity("label");
  const ModuleString s = deriveParity(p);
  checkSame(s, p.grammar.symbols(), cpfgString("label"));
  Deriver d(p.grammar);
  d.derive();
  Turtle t(p.grammar.symbols(), *p.turtle);
  CHECK(t.run(d.interpret(d.current())).internodes.size() == 3);  // SHOW is 0: no label reached
  SECTION("a label: the format filled as cpfg's sprintf fills it, at the turtle, in its colour") {
    std::string text = readFile(parityAsset("label/plant.l"));
    text.replace(text.find("#define SHOW 0"), 14, "#define SHOW 1");
    Grammar g = parseGrammar(text, "plant.l");
    Deriver dl(g);
    dl.derive();
    TurtleSettings ts = *p.turtle;
    ts.labelFormats = g.strings();
    const Skeleton sk = Turtle(g.symbols(), ts).run(dl.interpret(dl.current()));
    // I(1) I(2) I(3): F(x) then [;(5)@L(" %.f, (%g)", x, x / 2)] at the F's end, y = 1, 3, 6.
    REQUIRE(sk.internodes.size() == 3);
    REQUIRE(sk.labels.size() == 3);
    const char* want[] = {" 1, (0.5)", " 2, (1)", " 3, (1.5)"};
    const double y[] = {1, 3, 6};
    for (size_t k = 0; k < 3; ++k) {
      CHECK(sk.labels[k].text == want[k]);
      CHECK(sk.labels[k].position.x == Approx(0).margin(1e-12));
      CHECK(sk.labels[k].position.y == Approx(y[k]));
      CHECK(sk.labels[k].position.z == Approx(0).margin(1e-12));
      CHECK(sk.labels[k].color == 5);
      CHECK(glm::length(sk.labels[k].position - sk.internodes[k].end) < 1e-9);
    }
    ts.labelFormats = nullptr;
    CHECK_THROWS_WITH(Turtle(g.symbols(), ts).run(dl.interpret(dl.current())), Catch::Contains("cpfg's '@L' names no format"));
  }
  SECTION("a format whose conversions outnumber the values, or are not numbers, is an error") {
    Grammar g = parseGrammar("axiom: A\nhomomorphism\nA --> F@L(\"%g and %g\", 1)\nendlsystem\n", "t.l");
    Deriver dg(g);
    TurtleSettings ts = *p.turtle;
    ts.labelFormats = g.strings();
    CHECK_THROWS_WITH(Turtle(g.symbols(), ts).run(dg.interpret(dg.current())),
                      Catch::Contains("cpfg's '@L(\"%g and %g\", ...)' has 2 conversions for 1 values"));
    Grammar h = parseGrammar("axiom: A\nhomomorphism\nA --> F@L(\"%s\", 1)\nendlsystem\n", "t.l");
    Deriver dh(h);
    ts.labelFormats = h.strings();
    CHECK_THROWS_WITH(Turtle(h.symbols(), ts).run(dh.interpret(dh.current())), Catch::Contains("is not a number's"));
  }
  SECTION("elsewhere @L is an error") {
    CHECK_THROWS_WITH(parseGrammar("axiom: A\nA --> F@L(\"x\")\n", "t.l"),
                      Catch::Contains("t.l:2:8: error: cpfg's '@L' (label) is supported only in interpretation rules"));
    CHECK_THROWS_WITH(parseGrammar("axiom: F@L(\"x\")\n", "t.l"),
                      Catch::Contains("t.l:1:9: error: cpfg's '@L' (label) is supported only in interpretation rules"));
    CHECK_THROWS_WITH(parseGrammar("axiom: A\ninterpretation:\nA --> F@L(\"x\")\n", "t.lsys"),
                      Catch::Contains("t.lsys:3:8: error: cpfg's '@L' (label) is not supported"));
  }
}
