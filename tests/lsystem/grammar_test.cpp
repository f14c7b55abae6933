#include <catch2/catch.hpp>

#include <filesystem>

#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

/// The diagnostics (without source lines) of parsing text, one per line; "" when it parses.
std::string errorsOf(const std::string& text, const GrammarOverrides& o = {}) {
  try {
    parseGrammar(text, "g.lsys", o);
  } catch (const InputError& e) {
    std::string out;
    for (const Diagnostic& d : e.diagnostics()) {
      if (!out.empty()) out += '\n';
      Diagnostic bare = d;
      bare.sourceLine.clear();
      out += bare.format();
    }
    return out;
  }
  return "";
}

/// The error for a production that can never apply: `what` is its position and reason
/// after "g.lsys:", as parseGrammar words them.
std::string neverApplies(const std::string& what) { return "g.lsys:" + what + ", so this production never applies"; }

}  // namespace

TEST_CASE("parseGrammar headers", "[lsystem]") {
  const char* text = R"(/* a comment
   over two lines */
lsystem: demo   // trailing comment
derivation length: 3
seed: 12345678901234
angle: 22.5
#define n 2
module Apex, Leaf
axiom: Apex(n)Leaf
Apex(x) --> F(x)Apex(x+1)
endlsystem
anything after endlsystem is ignored -->
)";
  Grammar g = parseGrammar(text, "demo.lsys");
  CHECK(g.name() == "demo");
  CHECK(g.fileName() == "demo.lsys");
  CHECK(g.derivationLength() == 3);
  CHECK(g.seed() == 12345678901234ull);
  CHECK(g.angleDeg().value() == 22.5);
  CHECK(g.defineNames() == std::vector<std::string>{"n"});
  CHECK(g.productionCount() == 1);
  CHECK_FALSE(g.hasInterpretation());
  CHECK(formatModuleString(g.axiom(), g.symbols()) == "Apex(2)Leaf");
  CHECK(formatModuleString(derive(g), g.symbols()) == "F(2)F(3)F(4)Apex(5)Leaf");
  SECTION("built-in turtle symbols come first in the symbol table") {
    for (size_t i = 0; i < std::size(kTurtleSymbols); ++i) CHECK(g.symbols().name(static_cast<SymbolId>(i)) == kTurtleSymbols[i]);
  }
  SECTION("defaults without headers") {
    Grammar h = parseGrammar("axiom: F\n", "dir/plain.lsys");
    CHECK(h.name() == "plain");
    CHECK(h.derivationLength() == 0);
    CHECK(h.seed() == 0);
    CHECK_FALSE(h.angleDeg().has_value());
  }
}

TEST_CASE("parseGrammar tokenizing module strings", "[lsystem]") {
  SECTION("longest match among declared names") {
    Grammar g = parseGrammar("module A, Ap, Apex\naxiom: ApexApApAx\n", "g.lsys");
    const ModuleString& s = g.axiom();
    std::vector<std::string> names;
    for (SymbolId id : s.symbols) names.push_back(g.symbols().name(id));
    CHECK(names == std::vector<std::string>{"Apex", "Ap", "Ap", "A", "x"});
  }
  SECTION("built-in multi-character symbols and named surfaces") {
    Grammar g = parseGrammar("axiom: @Ts(0.2)@v@O(1)~l(2)F\n", "g.lsys");
    std::vector<std::string> names;
    for (SymbolId id : g.axiom().symbols) names.push_back(g.symbols().name(id));
    CHECK(names == std::vector<std::string>{"@Ts", "@v", "@O", "~l", "F"});
  }
  SECTION("whitespace between modules and inside parameters is ignored") {
    Grammar g = parseGrammar("axiom: F ( 1 , 2 ) [ + F ]\n", "g.lsys");
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "F(1,2)[+F]");
  }
  SECTION("digits are module symbols in strings") {
    Grammar g = parseGrammar("axiom: F1F0(3)\n", "g.lsys");
    CHECK(g.axiom().size() == 4);
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "F1F0(3)");
  }
  SECTION("parseModuleString") {
    SymbolTable t;
    ModuleString s = parseModuleString("A(1+1)B(2*3)", t);
    CHECK(formatModuleString(s, t) == "A(2)B(6)");
  }
}

TEST_CASE("parseGrammar overrides", "[lsystem]") {
  const char* text = "derivation length: 2\nseed: 1\n#define a 2\n#define b a*10\naxiom: A(b)\n";
  GrammarOverrides o;
  o.defines.push_back({"a", 5, {}});
  o.derivationLength = 9;
  o.seed = 77;
  Grammar g = parseGrammar(text, "g.lsys", o);
  CHECK(g.define("a").value() == 5);
  CHECK(g.define("b").value() == 50);  // later #defines see the override
  CHECK(g.derivationLength() == 9);
  CHECK(g.seed() == 77);
  CHECK(formatModuleString(g.axiom(), g.symbols()) == "A(50)");
  SECTION("an unknown #define is an error at the override's location") {
    GrammarOverrides bad;
    bad.defines.push_back({"bb", 1, SourceLoc{"species.yaml", 4, 7}});
    CHECK(errorsOf(text, bad) == "species.yaml:4:7: error: no '#define bb' in g.lsys (did you mean 'b'?)");
    GrammarOverrides cli;
    cli.defines.push_back({"zzz", 1, {}});
    CHECK(errorsOf(text, cli) == "g.lsys: error: no '#define zzz' in g.lsys");
  }
}

TEST_CASE("parseGrammar errors: exact messages and positions", "[lsystem]") {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"axiom: F\n/* open", "g.lsys:2:1: error: unterminated comment '/*'"},
      {"#define\naxiom: F\n", "g.lsys:1:8: error: expected a name after '#define'"},
      {"#define x 1\n#define x 2\naxiom: F\n", "g.lsys:2:9: error: 'x' is already defined at line 1"},
      {"#define x\naxiom: F\n", "g.lsys:1:10: error: expected a value after '#define x'"},
      {"#defne x 1\naxiom: F\n", "g.lsys:1:1: error: unknown directive '#defne' (did you mean '#define'?)"},
      {"module 9a\naxiom: F\n", "g.lsys:1:8: error: invalid module name '9a' (letters, digits and '_', starting with a letter)"},
      {"axiom: F\nendlsystem now\n", "g.lsys:2:12: error: unexpected text after 'endlsystem'"},
      {"axoim: F\n", "g.lsys:1:1: error: unknown header 'axoim:' (did you mean 'axiom'?)\ng.lsys: error: missing 'axiom:'"},
      {"axiom: F\nF F F\n", "g.lsys:2:1: error: expected a production ('pred --> successor') or a header such as 'axiom:'"},
      {"axiom: F\naxiom: G\n", "g.lsys:2:1: error: duplicate 'axiom:' (first at line 1)"},
      {"derivation length: 2.5\naxiom: F\n", "g.lsys:1:20: error: derivation length must be a whole number from 0 to 1000000, got 2.5"},
      {"seed: -3\naxiom: F\n", "g.lsys:1:7: error: seed must be a non-negative integer below 2^64, got '-3'"},
      {"axiom:\n", "g.lsys:1:7: error: the axiom is empty"},
      {"ignore: F(1)\naxiom: F\n", "g.lsys:1:9: error: 'ignore:' lists symbols without parameters"},
      {"ignore: [\naxiom: F\n", "g.lsys:1:9: error: brackets cannot be ignored in Sprig's notation: context matching always follows them"},
      {"ignore: F\nconsider: G\naxiom: F\n", "g.lsys:2:1: error: use either 'ignore:' or 'consider:', not both"},
      {"maximum depth: 2\naxiom: F\n", "g.lsys:1:1: error: 'maximum depth:' belongs in a 'decomposition:' or 'interpretation:' block"},
      {"axiom: F\ndecomposition:\nmaximum depth: 0\n", "g.lsys:3:16: error: maximum depth must be a whole number from 1 to 1000000, got 0"},
      {"axiom: F\n --> F\n", "g.lsys:2:2: error: missing predecessor before '-->'"},
      {"axiom: F\n[ --> F\n", "g.lsys:2:1: error: a bracket cannot be a predecessor"},
      {"axiom: F\ndecomposition:\nA < B --> F\n", "g.lsys:3:1: error: context is not allowed in decomposition rules"},
      {"axiom: F\ninterpretation:\nB > A --> F\n", "g.lsys:3:5: error: context is not allowed in interpretation rules"},
      {"axiom: F\nA : --> F\n", "g.lsys:2:3: error: missing condition after ':' (write '*' for none)"},
      {"axiom: F\nA -->\n", "g.lsys:2:6: error: missing successor (write '*' for the empty string)"},
      {"axiom: F\nA --> B :\n", "g.lsys:2:9: error: missing weight after ':'"},
      {"axiom: F\nA --> B : -1\n", "g.lsys:2:11: error: a weight must not be negative, got -1"},
      {"axiom: F\nA(2) --> B\n", "g.lsys:2:3: error: expected a parameter name, got '2'"},
      {"axiom: F\nA(x,x) --> B\n", "g.lsys:2:5: error: parameter 'x' is already used in this production"},
      {"#define k 1\naxiom: F\nA(k) --> B\n", "g.lsys:3:3: error: parameter 'k' has the name of a #define"},
      {"axiom: F\n[A < B --> F\n", "g.lsys:2:1: error: brackets are not allowed in a left context"},
      {"axiom: F\nA(x) --> B(sine(x))\n", "g.lsys:2:12: error: unknown function 'sine' (did you mean 'sin'?)"},
      {"axiom: F\nA(x) --> B(min(x))\n", "g.lsys:2:12: error: function 'min' takes 2 arguments, got 1"},
      {"axiom: F\nA(x) --> B(sin(x,x))\n", "g.lsys:2:12: error: function 'sin' takes 1 argument, got 2"},
      {"axiom: F\nA(len) --> B(lem*2)\n", "g.lsys:2:14: error: unknown name 'lem' (did you mean 'len'?)"},
      {"axiom: F\nA(x) --> B(x # 2)\n", "g.lsys:2:14: error: unexpected character '#' in expression"},
      {"axiom: F\nA(x) --> B((x+1)\n", "g.lsys:2:11: error: missing ')' after the parameters of 'B'"},
      {"axiom: F\nA(x) --> B(x+)\n", "g.lsys:2:14: error: expected a number, a name or '(' at the end of the expression"},
      {"axiom: F\nA(x) --> B(x 2)\n", "g.lsys:2:14: error: expected an operator, got '2'"},
      {"axiom: F\nA(x) --> B(1.2.3)\n", "g.lsys:2:12: error: malformed number '1.2.3'"},
      {"axiom: F\nA(x) --> B)\n", "g.lsys:2:11: error: unmatched ')'"},
      {"axiom: F\nA(x) --> (B\n", "g.lsys:2:10: error: unexpected '(' (parameters must follow a module name)"},
      {"axiom: F\nA(x) --> B(x,)\n", "g.lsys:2:14: error: empty parameter in 'B'"},
      {"seed: 1\n", "g.lsys: error: missing 'axiom:'"},
      {"angle: x\naxiom: F\n", "g.lsys:1:8: error: unknown name 'x'"},
      {"angle: ran(2)\naxiom: F\n", "g.lsys:1:8: error: angle must be a constant"},
      {"axiom: F(1/0)\n", "g.lsys:1:10: error: parameter is not finite (inf)"},
      {"axiom: F\nA(x) --> B(x) : x\n", "g.lsys:2:17: error: unknown name 'x'"},
      {"axiom: F(ran(1))\naxiom: G\n", "g.lsys:2:1: error: duplicate 'axiom:' (first at line 1)"},
  };
  for (const Case& c : cases) {
    INFO(c.text);
    CHECK(errorsOf(c.text) == c.message);
  }
}

TEST_CASE("parseGrammar unbalanced brackets", "[lsystem]") {
  SECTION("in the axiom") {
    CHECK(errorsOf("axiom: F[+F\n") == "g.lsys:1:9: error: unclosed '[' in the axiom (no matching ']')");
    CHECK(errorsOf("axiom: F]F\n") == "g.lsys:1:9: error: unmatched ']' in the axiom");
    CHECK(errorsOf("axiom: [F[F]\n") == "g.lsys:1:8: error: unclosed '[' in the axiom (no matching ']')");
  }
  SECTION("in a successor, in every block") {
    CHECK(errorsOf("axiom: A\nA --> F[+A][-A\n") == "g.lsys:2:12: error: unclosed '[' in the successor (no matching ']')");
    CHECK(errorsOf("axiom: A\nA --> F]+A[\n") ==
          "g.lsys:2:8: error: unmatched ']' in the successor\n"
          "g.lsys:2:11: error: unclosed '[' in the successor (no matching ']')");
    CHECK(errorsOf("axiom: A\ninterpretation:\nA --> [F\n") == "g.lsys:3:7: error: unclosed '[' in the successor (no matching ']')");
    CHECK(errorsOf("axiom: A\ndecomposition:\nA --> F]\n") == "g.lsys:3:8: error: unmatched ']' in the successor");
  }
  SECTION("balanced strings and the empty successor parse") {
    CHECK(errorsOf("axiom: [F][[F]F]\nA --> [F[+A]][-A]\nB --> *\n").empty());
  }
}

TEST_CASE("parseGrammar parameter counts that never match", "[lsystem]") {
  SECTION("a predecessor whose parameter count no written module has") {
    CHECK(errorsOf("axiom: A\nA(x) --> F(x)B(x)\n") ==
          neverApplies("2:1: error: predecessor 'A(x)' has 1 parameter, but 'A' is only written with 0 parameters (as at line 1:8)"));
    CHECK(errorsOf("axiom: B(1,2)\nB(a,b) --> A(a)B(a,b)A(a,b,a)\nA(x, y) --> F\n") ==
          neverApplies("3:1: error: predecessor 'A(x, y)' has 2 parameters, but 'A' is only written with 1 or 3 parameters "
                       "(as at line 2:12)"));
    CHECK(errorsOf("axiom: F(1)\nF --> GG\n") ==
          neverApplies("2:1: error: predecessor 'F' has 0 parameters, but 'F' is only written with 1 parameter (as at line 1:8)"));
  }
  SECTION("a context whose parameter count no written module has") {
    CHECK(errorsOf("axiom: B(1)A\nB(x) < A --> A\nB --> C\n") ==
          neverApplies("3:1: error: predecessor 'B' has 0 parameters, but 'B' is only written with 1 parameter (as at line 1:8)"));
    CHECK(errorsOf("axiom: BA\nB(x) < A --> A\n") ==
          neverApplies("2:1: error: context 'B(x)' has 1 parameter, but 'B' is only written with 0 parameters (as at line 1:8)"));
  }
  SECTION("checked only when the rest of the file parses (no follow-on errors)") {
    CHECK(errorsOf("axiom: B\nA --> B(1,)\nB(x) --> C\n") == "g.lsys:2:11: error: empty parameter in 'B'");
  }
  SECTION("any matching count is enough; symbols never written are left alone") {
    CHECK(errorsOf("axiom: A A(1)\nA --> B\nA(x) --> A(x+1)\nC(x,y) --> D\n").empty());
    CHECK(errorsOf("axiom: A\nA --> B(1)\ninterpretation:\nB(x) --> F(x)\n").empty());
  }
}

TEST_CASE("parseGrammar a user module written with a count no production takes", "[lsystem]") {
  CHECK(errorsOf("axiom: A(1,2)\nA(x) --> A(x+1)\n") ==
        "g.lsys:1:8: error: module 'A' is written here with 2 parameters, but its production 'A(x)' (line 2:1) takes 1 "
        "parameter: a production matches a module only with its own parameter count, so this module is never rewritten");
  // Turtle commands take optional parameters: F and F(2) together are fine.
  CHECK(errorsOf("axiom: A\nA --> F F(2) +(30) + A\nF --> F F\n").empty());
}

TEST_CASE("parseGrammar stochastic productions whose weights are all zero", "[lsystem]") {
  CHECK(errorsOf("axiom: A\nA --> F : 0\nA --> G : 0\n") ==
        "g.lsys:2:1: error: every stochastic production of 'A' has weight 0 (lines 2, 3): at least one weight must be positive");
  CHECK(errorsOf("axiom: A\nA --> F : 0\nA --> G : 0.5\n").empty());
}

TEST_CASE("parseGrammar text that is not UTF-8 is one error naming the byte", "[lsystem]") {
  std::string text = "axiom: F\nF --> F";
  text += '\0';
  text += "\xff\x01 F\n";
  CHECK(errorsOf(text) == "g.lsys:2:8: error: byte 0x00 (NUL) at byte offset 16 is not text: a grammar file must be UTF-8 "
                          "text (is this a binary file?)");
  CHECK(errorsOf("axiom: F\nF --> F // caf\xc3\xa9\n").empty());  // UTF-8 in a comment is text
}

TEST_CASE("parseGrammar deep nesting is an error, not a crash", "[lsystem]") {
  std::string text = "axiom: F\nA(x) --> B(" + std::string(50, '(') + "x" + std::string(50, ')') + ")\n";
  CHECK(errorsOf(text) == "g.lsys:2:60: error: expression is nested too deeply (more than 48 levels)");
  std::string minus = "axiom: F\nA(x) --> B(" + std::string(5000, '-') + "x)\n";
  CHECK(errorsOf(minus) == "g.lsys:2:60: error: expression is nested too deeply (more than 48 levels)");
}

TEST_CASE("parseGrammar collects every error before throwing", "[lsystem]") {
  const char* text = "axiom: F\nA(x) --> B(y)\nC --> D(sine(1))\nderivaton length: 3\n";
  CHECK(errorsOf(text) ==
        "g.lsys:2:12: error: unknown name 'y' (did you mean 'x'?)\n"
        "g.lsys:3:9: error: unknown function 'sine' (did you mean 'sin'?)\n"
        "g.lsys:4:1: error: unknown header 'derivaton length:' (did you mean 'derivation length'?)");
  SECTION("the formatted error shows the line and a caret") {
    try {
      parseGrammar("axiom: F\nA(x) --> B(y)\n", "g.lsys");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()) == "g.lsys:2:12: error: unknown name 'y' (did you mean 'x'?)\n  A(x) --> B(y)\n             ^");
    }
  }
}

TEST_CASE("loadGrammar", "[lsystem]") {
  try {
    loadGrammar("/nonexistent/x.lsys");
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == "/nonexistent/x.lsys: error: cannot find file");
  }
}

TEST_CASE("parseGrammar production forms", "[lsystem]") {
  SECTION("-> and --> arrows, * contexts and conditions") {
    Grammar g = parseGrammar("axiom: AB\nA -> X\n* < B > * : * --> Y\n", "g.lsys");
    CHECK(formatModuleString(derive(g, DeriveOptions{.steps = 1}), g.symbols()) == "XY");
  }
  SECTION("a condition may use comparison operators next to context markers") {
    Grammar g = parseGrammar("axiom: B(1)A(2)C(3)\nB(a) < A(x) > C(c) : a<x && x<c --> X\n", "g.lsys");
    CHECK(formatModuleString(derive(g, DeriveOptions{.steps = 1}), g.symbols()) == "B(1)XC(3)");
  }
  SECTION("lpfg-style module declarations with types") {
    Grammar g = parseGrammar("module Apex(float), Bud\naxiom: Apex(1)Bud\n", "g.lsys");
    CHECK(g.axiom().size() == 2);
  }
  SECTION("Windows line endings") {
    Grammar g = parseGrammar("axiom: A\r\nA --> BB\r\n", "g.lsys");
    CHECK(formatModuleString(derive(g, DeriveOptions{.steps = 1}), g.symbols()) == "BB");
  }
}

TEST_CASE("loadGrammar every shipped grammar", "[lsystem]") {
  // Every grammars/*.lsys parses (brackets balanced, every predecessor can match) and has
  // a derivation length; a grammar edit that breaks one fails here, not in the gallery.
  size_t count = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(SPRIG_SOURCE_DIR) + "/grammars")) {
    if (entry.path().extension() != ".lsys") continue;
    INFO(entry.path().string());
    Grammar g = loadGrammar(entry.path().string());
    CHECK(g.axiom().size() > 0);
    CHECK(g.derivationLength() > 0);
    CHECK(g.productionCount() > 0);
    CHECK(g.warnings().empty());  // no shipped module string reads as an undeclared word
    ++count;
  }
  CHECK(count >= 12);  // ABOP 1.24a-f, 1.31a, 2.6-2.8, shrub, conifer, ...
}

namespace {

/// The warnings and notes of parsing text, formatted without source lines, one per line.
std::string warningsOf(const std::string& text, const std::string& fileName = "g.lsys", const GrammarOverrides& o = {}) {
  std::string out;
  const Grammar g = parseGrammar(text, fileName, o);  // warnings() refers into g
  for (const Diagnostic& d : g.warnings()) {
    Diagnostic bare = d;
    bare.sourceLine.clear();
    out += (out.empty() ? "" : "\n") + bare.format();
  }
  return out;
}

}  // namespace

TEST_CASE("Grammar::warnings: a multi-letter name written without its module declaration", "[lsystem]") {
  const std::string rules = "axiom: A Leaf(0)\nA --> F Leaf(1) [+Bud] Leaf(2)\nderivation length: 2\n";
  SECTION("one warning per word, at its first place") {
    CHECK(warningsOf(rules) ==
          "g.lsys:1:10: warning: 'Leaf' is read as 4 one-letter modules; declare it with 'module Leaf' to make it one module\n"
          "g.lsys:2:19: warning: 'Bud' is read as 3 one-letter modules; declare it with 'module Bud' to make it one module");
    // The grammar is still what the text says: L e a f(0) are four modules.
    Grammar g = parseGrammar(rules, "g.lsys");
    CHECK(formatModuleString(g.axiom(), g.symbols()) == "ALeaf(0)");
    CHECK(g.axiom().size() == 5);
  }
  SECTION("declared, the word is one module and there is no warning") {
    Grammar g = parseGrammar("module Leaf, Bud\n" + rules, "g.lsys");
    CHECK(g.warnings().empty());
    CHECK(g.axiom().size() == 2);
  }
  SECTION("what is not such a word") {
    CHECK(warningsOf("axiom: FFF A(1)B(2)C lea Le F(1)ab\nderivation length: 1\n").empty());  // no capitalized run of 3
    CHECK(warningsOf("axiom: L e a f\nderivation length: 1\n").empty());                      // spaced letters
    CHECK(warningsOf("axiom: L(1)eaf\nderivation length: 1\n").empty());                      // a parameter ends the run
    CHECK(warningsOf("axiom: Leaf\nderivation length: 1\n", "g.l").empty());                  // cpfg has no declarations
  }
  SECTION("a predecessor counts too") {
    CHECK(warningsOf("axiom: A\nApex --> F\nderivation length: 1\n") ==
          "g.lsys:2:1: warning: 'Apex' is read as 4 one-letter modules; declare it with 'module Apex' to make it one module");
  }
}

TEST_CASE("Grammar::warnings: a species' steps replacing the grammar's derivation length is a note", "[lsystem]") {
  const std::string text = "axiom: A\nA --> AB\nderivation length: 10\n";
  GrammarOverrides o;
  o.derivationLength = 12;
  CHECK(warningsOf(text, "g.lsys", o).empty());  // no place to point at: a command-line --steps
  o.derivationLengthLoc = SourceLoc{"s.yaml", 3, 8};
  CHECK(warningsOf(text, "g.lsys", o) == "s.yaml:3:8: note: 12 steps replace the grammar's 'derivation length: 10' (g.lsys:3)");
  o.derivationLength = 10;
  CHECK(warningsOf(text, "g.lsys", o).empty());  // the same value replaces nothing
  o.derivationLength = 4;
  CHECK(warningsOf("axiom: A\nA --> AB\n", "g.lsys", o).empty());  // the grammar writes no length
}

TEST_CASE("parseGrammar in cpfg's notation: a module written with a count no production takes is a warning", "[lsystem][cpfg]") {
  // cpfg derives the file and never rewrites the module (vlab's two-trees writes 'L' beside
  // 'L(del,vig)'); Sprig derives it the same and warns.
  const std::string text = "axiom: A(1,2)\nA(x) --> A(x+1)\n";
  CHECK(warningsOf(text, "g.l") ==
        "g.l:1:8: warning: module 'A' is written here with 2 parameters, but its production 'A(x)' (line 2:1) takes 1 "
        "parameter: a production matches a module only with its own parameter count, so this module is never rewritten, "
        "as in cpfg");
  Grammar g = parseGrammar(text, "g.l");
  Deriver d(g, DeriveOptions{.steps = 2});
  CHECK(formatModuleString(d.derive(), d.symbols()) == "A(1,2)");
}
