#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <thread>

#include "core/rng.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

std::string asset(const std::string& name) { return std::string(SPRIG_SOURCE_DIR) + "/tests/assets/lsystem/" + name; }

/// The string after `steps` derivation steps of text, in grammar notation.
std::string deriveText(const std::string& text, int steps, uint64_t seed = 0) {
  Grammar g = parseGrammar(text, "t.lsys");
  DeriveOptions opt;
  opt.steps = steps;
  opt.seed = seed;
  Deriver d(g, opt);
  return formatModuleString(d.derive(), d.symbols());
}

/// A grammar and the string one derivation step gives, in a scenario.
struct OneStep {
  const char* scenario;
  const char* grammar;
  const char* expected;
};

/// The message of the InputError fn throws ("" when it does not throw).
template <class Fn>
std::string errorOf(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// Reference context-sensitive rewriting over single-character, parameterless strings,
/// written independently of the engine, with lpfg's bracket rules: a right context skips
/// whole [...] branches and fails at `]`; a left context skips `[` and whole branches
/// ending in `]`; symbols in `ignore` are skipped on both sides.
struct NaiveRule {
  char left = 0, pred = 0, right = 0;  // 0: no context
  std::string successor;
};

std::string naiveStep(const std::string& s, const std::vector<NaiveRule>& rules, const std::string& ignore) {
  auto ignored = [&](char c) { return ignore.find(c) != std::string::npos; };
  auto leftOf = [&](size_t i) -> char {
    int depth = 0;
    for (ptrdiff_t j = static_cast<ptrdiff_t>(i) - 1; j >= 0; --j) {
      char c = s[j];
      if (c == ']') ++depth;
      else if (c == '[') { if (depth > 0) --depth; }
      else if (depth == 0 && !ignored(c)) return c;
    }
    return 0;
  };
  auto rightOf = [&](size_t i) -> char {
    int depth = 0;
    for (size_t j = i + 1; j < s.size(); ++j) {
      char c = s[j];
      if (c == '[') ++depth;
      else if (c == ']') { if (depth == 0) return 0; --depth; }
      else if (depth == 0 && !ignored(c)) return c;
    }
    return 0;
  };
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    const NaiveRule* hit = nullptr;
    for (const NaiveRule& r : rules) {
      if (r.pred != s[i]) continue;
      if (r.left && leftOf(i) != r.left) continue;
      if (r.right && rightOf(i) != r.right) continue;
      hit = &r;
      break;
    }
    out += hit ? hit->successor : std::string(1, s[i]);
  }
  return out;
}

}  // namespace

TEST_CASE("Deriver::derive ABOP figure 1.24", "[lsystem]") {
  // Exact counts from the productions' own recurrences (F: drawn segments).
  SECTION("1.24a: F -> F[+F]F[-F]F, n=5: 7811 modules, 3125 segments") {
    Grammar g = loadGrammar(asset("abop_1_24a.lsys"));
    ModuleString s = derive(g);
    CHECK(s.size() == 7811);
    CHECK(countSymbol(s, g.symbols(), "F") == 3125);
    CHECK(g.angleDeg().value() == 25.7);
    CHECK(g.derivationLength() == 5);
    CHECK(g.name() == "abop_1_24a");
  }
  SECTION("1.24b: 13 modules per F, n=5") {
    Grammar g = loadGrammar(asset("abop_1_24b.lsys"));
    ModuleString s = derive(g);
    CHECK(countSymbol(s, g.symbols(), "F") == 3125);
    CHECK(s.size() == 1 + 12 * (1 + 5 + 25 + 125 + 625));
  }
  SECTION("1.24c: 20 modules with 8 F per F, n=4") {
    Grammar g = loadGrammar(asset("abop_1_24c.lsys"));
    ModuleString s = derive(g);
    CHECK(countSymbol(s, g.symbols(), "F") == 4096);
    CHECK(s.size() == 1 + 19 * (1 + 8 + 64 + 512));
  }
  // Node rewriting: X and F counts follow a linear recurrence.
  struct NodeCase {
    const char* file;
    int xPerX, fPerX, otherPerX;  // modules an X becomes
  };
  for (NodeCase c : {NodeCase{"abop_1_24d.lsys", 3, 2, 7}, NodeCase{"abop_1_24e.lsys", 3, 2, 6},
                     NodeCase{"abop_1_24f.lsys", 4, 3, 11}}) {
    SECTION(c.file) {
      Grammar g = loadGrammar(asset(c.file));
      ModuleString s = derive(g);
      uint64_t x = 1, f = 0, other = 0;
      for (int k = 0; k < g.derivationLength(); ++k) {
        uint64_t nx = x * c.xPerX, nf = 2 * f + x * c.fPerX, no = other + x * c.otherPerX;
        x = nx, f = nf, other = no;
      }
      CHECK(countSymbol(s, g.symbols(), "X") == x);
      CHECK(countSymbol(s, g.symbols(), "F") == f);
      CHECK(s.size() == x + f + other);
    }
  }
}

TEST_CASE("Deriver::step ABOP eq 1.8", "[lsystem]") {
  const char* text = R"(
axiom: B(2)A(4,4)
A(x,y) : y<=3 -> A(x*2,x+y)
A(x,y) : y>3 -> B(x)A(x/y,0)
B(x) : x<1 -> C
B(x) : x>=1 -> B(x-1)
)";
  Grammar g = parseGrammar(text, "eq18.lsys");
  Deriver d(g);
  CHECK(formatModuleString(d.current(), d.symbols()) == "B(2)A(4,4)");
  CHECK(formatModuleString(d.step(), d.symbols()) == "B(1)B(4)A(1,0)");
  CHECK(formatModuleString(d.step(), d.symbols()) == "B(0)B(3)A(2,1)");
  CHECK(formatModuleString(d.step(), d.symbols()) == "CB(2)A(4,3)");
  CHECK(formatModuleString(d.step(), d.symbols()) == "CB(1)A(8,7)");
  CHECK(formatModuleString(d.step(), d.symbols()) == "CB(0)B(8)A(1.1428571428571428,0)");
  CHECK(d.stepsDone() == 5);
  SECTION("restart begins again from the axiom") {
    d.restart();
    CHECK(d.stepsDone() == 0);
    CHECK(formatModuleString(d.current(), d.symbols()) == "B(2)A(4,4)");
    CHECK(formatModuleString(d.step(), d.symbols()) == "B(1)B(4)A(1,0)");
  }
}

TEST_CASE("Deriver::derive first match wins, unmatched modules are copied", "[lsystem]") {
  CHECK(deriveText("axiom: A(1)B\nA(x) : x>0 --> X\nA(x) --> Y\n", 1) == "XB");
  CHECK(deriveText("axiom: A(0)B\nA(x) : x>0 --> X\nA(x) --> Y\n", 1) == "YB");
  CHECK(deriveText("axiom: A(1,2)A(3)\nA(x) --> X\nA(x,y) : x > 5 --> Y\n", 1) == "A(1,2)X");  // parameter count differs: no match
  CHECK(deriveText("axiom: AB\nA --> *\n", 1) == "B");               // `*` successor: erase
  CHECK(deriveText("axiom: A(3)\nA(x) : * --> A(x+1)\n", 4) == "A(7)");
}

TEST_CASE("Deriver::derive stochastic productions", "[lsystem]") {
  const char* text = R"(
axiom: AAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAAA
A --> B : 25
A --> C : 75
)";
  SECTION("same seed gives the same string; different seeds differ") {
    CHECK(deriveText(text, 1, 7) == deriveText(text, 1, 7));
    CHECK(deriveText(text, 1, 7) != deriveText(text, 1, 8));
  }
  SECTION("the grammar's seed: and the seed override") {
    std::string withSeed = std::string("seed: 7\n") + text;
    Grammar g = parseGrammar(withSeed, "t.lsys");
    CHECK(g.seed() == 7);
    Deriver d(g, DeriveOptions{.steps = 1});
    CHECK(formatModuleString(d.derive(), d.symbols()) == deriveText(text, 1, 7));
    GrammarOverrides o;
    o.seed = 8;
    Grammar g8 = parseGrammar(withSeed, "t.lsys", o);
    CHECK(formatModuleString(derive(g8, DeriveOptions{.steps = 1}), g8.symbols()) == deriveText(text, 1, 8));
  }
  SECTION("each module's choice depends only on (seed, step, index)") {
    // Appending modules leaves the earlier choices unchanged.
    std::string longer = std::string(text);
    longer.replace(longer.find("AAAA"), 4, "AAAAA");
    std::string a = deriveText(text, 1, 3), b = deriveText(longer, 1, 3);
    CHECK(b.substr(0, a.size()) == a);
  }
  SECTION("the same string whatever the number of threads deriving") {
    Grammar g = loadGrammar(std::string(SPRIG_SOURCE_DIR) + "/tests/assets/lsystem/stochastic_bush.lsys");
    std::string reference = formatModuleString(derive(g), g.symbols());
    std::vector<std::string> results(4);
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t)
      threads.emplace_back([&, t] { results[t] = formatModuleString(derive(g), g.symbols()); });
    for (auto& t : threads) t.join();
    for (const std::string& r : results) CHECK(r == reference);
  }
  SECTION("weights set the frequencies (cpfg percentages)") {
    std::string many = "axiom: ";
    for (int i = 0; i < 20000; ++i) many += 'A';
    many += "\nA --> B : 25\nA --> C : 75\n";
    Grammar g = parseGrammar(many, "t.lsys");
    ModuleString s = derive(g, DeriveOptions{.steps = 1, .seed = 1});
    double b = static_cast<double>(countSymbol(s, g.symbols(), "B"));
    CHECK(countSymbol(s, g.symbols(), "B") + countSymbol(s, g.symbols(), "C") == 20000);
    CHECK(std::abs(b / 20000 - 0.25) < 0.02);  // 6.5 standard deviations
  }
  SECTION("any number of alternatives") {
    std::string t = "axiom: ";
    for (int i = 0; i < 5000; ++i) t += 'A';
    t += '\n';
    for (int k = 0; k < 100; ++k) t += "A --> B(" + std::to_string(k) + ") : 1\n";
    Grammar g = parseGrammar(t, "t.lsys");
    ModuleString s = derive(g, DeriveOptions{.steps = 1, .seed = 2});
    std::map<double, int> seen;
    for (size_t i = 0; i < s.size(); ++i) ++seen[s.paramsOf(i)[0]];
    CHECK(seen.size() == 100);  // each has probability 1 - 0.99^5000 of appearing
  }
  SECTION("a condition narrows the stochastic choice to the matching productions") {
    std::string t = "axiom: A(1)A(1)A(1)A(1)A(1)A(1)A(1)A(1)\nA(x) : x>5 --> B : 1\nA(x) : x<5 --> C : 1\n";
    CHECK(deriveText(t, 1, 4) == "CCCCCCCC");
  }
}

TEST_CASE("Deriver::derive context matching across brackets (lpfg rules)", "[lsystem]") {
  SECTION("one step of small grammars (each row: scenario, grammar, result)") {
    const OneStep rows[] = {
        {"right context skips whole branches", "axiom: A[B]C\nA > C --> X\n", "X[B]C"},
        {"right context skips whole branches", "axiom: A[B]C\nA > B --> X\n", "A[B]C"},
        {"right context skips whole branches", "axiom: A[B][D]C\nA > C --> X\n", "X[B][D]C"},
        {"right context fails at the end of the branch", "axiom: [A]C\nA > C --> X\n", "[A]C"},
        {"right context fails at the end of the branch", "axiom: [AB]C\nA > B --> X\n", "[XB]C"},
        {"left context skips `[` into the parent", "axiom: B[A]\nB < A --> X\n", "B[X]"},
        {"left context skips `[` into the parent", "axiom: B[[A]]\nB < A --> X\n", "B[[X]]"},
        {"left context skips whole branches that end in `]`", "axiom: B[C]A\nB < A --> X\n", "B[C]X"},
        {"left context skips whole branches that end in `]`", "axiom: B[C]A\nC < A --> X\n", "B[C]A"},
        {"left context skips whole branches that end in `]`", "axiom: B[C][D[E]]A\nB < A --> X\n", "B[C][D[E]]X"},
        {"ignore: and consider:", "axiom: B+A\nB < A --> X\n", "B+A"},
        {"ignore: and consider:", "ignore: +\naxiom: B+A\nB < A --> X\n", "B+X"},
        {"ignore: and consider:", "ignore: +-\naxiom: A-+B\nA > B --> X\n", "X-+B"},
        {"ignore: and consider:", "consider: AB\naxiom: BFG+A\nB < A --> X\n", "BFG+X"},
        {"ignore: and consider:", "consider: AB\naxiom: BFC+A\nC < A --> X\n", "BFC+A"},
        {"multi-module contexts", "axiom: ABCDE\nA B < C > D E --> X\n", "ABXDE"},
        {"multi-module contexts", "axiom: ABCDF\nA B < C > D E --> X\n", "ABCDF"},
        {"brackets in a right context", "axiom: A[B]C\nA > [B]C --> X\n", "X[B]C"},
        {"brackets in a right context", "axiom: A[B]C\nA > [D]C --> X\n", "A[B]C"},
        {"brackets in a right context", "axiom: A[BE]C\nA > [B]C --> X\n", "X[BE]C"},
        {"parameters from contexts", "axiom: A(1)B(2)C(4)\nA(x) < B(y) > C(z) --> B(x+y+z)\n", "A(1)B(7)C(4)"},
        {"parameters from contexts", "axiom: A(1)B(2)C C(3)\nA(x) < B(y) > C(z) --> X\n", "A(1)B(2)CC(3)"},  // C has no parameter
        {"contexts read the old string, not the one being written", "axiom: AAB\nA > A --> B\nA > B --> C\n", "BCB"},
    };
    for (const OneStep& r : rows) {
      INFO(r.scenario << ": " << r.grammar);
      CHECK(deriveText(r.grammar, 1) == r.expected);
    }
  }
  SECTION("ABOP 1.31a against an independent reference") {
    Grammar g = loadGrammar(asset("abop_1_31a.lsys"));
    std::vector<NaiveRule> rules = {
        {'0', '0', '0', "0"}, {'0', '0', '1', "1[+F1F1]"}, {'0', '1', '0', "1"}, {'0', '1', '1', "1"},
        {'1', '0', '0', "0"}, {'1', '0', '1', "1F1"},      {'1', '1', '0', "0"}, {'1', '1', '1', "0"},
        {0, '+', 0, "-"},     {0, '-', 0, "+"},
    };
    std::string s = "F1F1F1";
    Deriver d(g);
    for (int k = 1; k <= 30; ++k) {
      s = naiveStep(s, rules, "+-F");
      REQUIRE(formatModuleString(d.step(), d.symbols()) == s);
    }
    CHECK(d.current().size() == s.size());
  }
  SECTION("random context tables against the reference (seeded property test)") {
    for (uint64_t seed = 1; seed <= 40; ++seed) {
      INFO("seed " << seed);
      Rng rng(seed);
      const char* alphabet = "01";
      const char* successors[] = {"0", "1", "1[+F1]", "1F1", "0[-F0]1", "[1]0", "F"};
      std::vector<NaiveRule> rules;
      std::string text = "ignore: +-F\naxiom: F1[0F1]1F0[+1]0\n";
      for (int k = 0; k < 8; ++k) {
        NaiveRule r;
        r.pred = alphabet[rng.below(2)];
        if (rng.below(3)) r.left = alphabet[rng.below(2)];
        if (rng.below(3)) r.right = alphabet[rng.below(2)];
        r.successor = successors[rng.below(7)];
        rules.push_back(r);
        text += r.left ? std::string(1, r.left) + " < " : std::string();
        text += r.pred;
        text += r.right ? std::string(" > ") + r.right : std::string();
        text += " --> " + r.successor + "\n";
      }
      Grammar g = parseGrammar(text, "random.lsys");
      Deriver d(g, DeriveOptions{.maxModules = 1'000'000});
      std::string s = "F1[0F1]1F0[+1]0";
      for (int k = 1; k <= 8; ++k) {
        s = naiveStep(s, rules, "+-F");
        REQUIRE(formatModuleString(d.step(), d.symbols()) == s);
      }
    }
  }
}

TEST_CASE("Deriver::derive expression functions", "[lsystem]") {
  auto value = [](const std::string& expr) {
    Grammar g = parseGrammar("axiom: A\nA --> B(" + expr + ")\n", "t.lsys");
    ModuleString s = derive(g, DeriveOptions{.steps = 1});
    REQUIRE(s.size() == 1);
    REQUIRE(s.paramCount(0) == 1);
    return s.paramsOf(0)[0];
  };
  // Each {expression, value}: the expression as a successor parameter gives exactly (then
  // approximately) the value.
  struct Value {
    const char* expr;
    double value;
  };
  const Value exact[] = {
      {"1+2*3", 7},
      {"(1+2)*3", 9},
      {"7-2-1", 4},
      {"8/2/2", 2},
      {"2^3^2", 512},           // right-associative
      {"-2^2", -4},             // ^ binds tighter than unary minus
      {"2^-1", 0.5},
      {"3<4", 1},
      {"3<=3", 1},
      {"3>4", 0},
      {"4>=5", 0},
      {"2==2", 1},
      {"2!=2", 0},
      {"1&&0", 0},
      {"1||0", 1},
      {"!0", 1},
      {"!3", 0},
      {"1<2 && 2<3 || 0", 1},
      {"sqrt(16)", 4},
      {"exp(0)", 1},
      {"pow(2,10)", 1024},
      {"abs(-3)", 3},
      {"min(2,-5)", -5},
      {"max(2,-5)", 2},
      {"floor(-1.5)", -2},
      {"ceil(1.2)", 2},
      {"sign(-2)", -1},
      {"sign(0)", 0},
      {"sign(3)", 1},
      {"1.5e2", 150},
      {".5", 0.5},
  };
  const Value approximate[] = {
      {"sin(30)", 0.5},
      {"cos(60)", 0.5},
      {"tan(45)", 1},
      {"asin(0.5)", 30},
      {"acos(0.5)", 60},
      {"atan(1)", 45},
      {"atan2(1,-1)", 135},
      {"log(exp(2))", 2},
  };
  for (const Value& v : exact) {
    INFO(v.expr);
    CHECK(value(v.expr) == v.value);
  }
  for (const Value& v : approximate) {
    INFO(v.expr);
    CHECK(value(v.expr) == Approx(v.value));
  }
  SECTION("ran(x) is uniform in [0,x); nran(mean, sd) is normal; both seeded") {
    std::string axiom = "axiom: ";
    for (int i = 0; i < 4000; ++i) axiom += 'A';
    Grammar g = parseGrammar(axiom + "\nA --> B(ran(2), nran(10, 3))\n", "t.lsys");
    ModuleString s = derive(g, DeriveOptions{.steps = 1, .seed = 5});
    double sumU = 0, sumN = 0, sumN2 = 0;
    for (size_t i = 0; i < s.size(); ++i) {
      double u = s.paramsOf(i)[0], n = s.paramsOf(i)[1];
      REQUIRE(u >= 0);
      REQUIRE(u < 2);
      sumU += u, sumN += n, sumN2 += n * n;
    }
    double count = static_cast<double>(s.size());
    double meanN = sumN / count;
    CHECK(sumU / count == Approx(1).margin(0.05));
    CHECK(meanN == Approx(10).margin(0.2));
    CHECK(std::sqrt(sumN2 / count - meanN * meanN) == Approx(3).margin(0.2));
    ModuleString again = derive(g, DeriveOptions{.steps = 1, .seed = 5});
    CHECK(again.params == s.params);
  }
  SECTION("#define constants and formal parameters") {
    Grammar g = parseGrammar("#define r 0.5\n#define r2 r*r\naxiom: A(8)\nA(x) --> A(x*r2)\n", "t.lsys");
    CHECK(g.define("r2").value() == 0.25);
    CHECK(formatModuleString(derive(g, DeriveOptions{.steps = 2}), g.symbols()) == "A(0.5)");
  }
}

TEST_CASE("Deriver::derive decomposition and interpretation", "[lsystem]") {
  SECTION("decomposition applies after each step, recursively to maximum depth") {
    const char* text = R"(
axiom: A
A --> BA
decomposition:
maximum depth: 2
B --> CD
C --> EB
endlsystem
)";
    // B -> CD (depth 1) -> C -> EB (depth 2); the new B is not decomposed further.
    CHECK(deriveText(text, 1) == "EBDA");
    // Step 2: the B left undecomposed at depth 2 is decomposed in the next step.
    CHECK(deriveText(text, 2) == "EEBDDEBDA");
  }
  SECTION("the default maximum depth is 1") {
    CHECK(deriveText("axiom: A\nA --> BA\ndecomposition:\nB --> CD\nC --> X\n", 1) == "CDA");
  }
  SECTION("the axiom is decomposed too") {
    CHECK(deriveText("axiom: BB(1)\ndecomposition:\nB(x) --> X\nB --> Y\n", 0) == "YX");
  }
  SECTION("interpretation rules apply only when the turtle reads the string") {
    const char* text = R"(
axiom: A(1)
A(x) --> A(x+1)
interpretation:
maximum depth: 2
A(x) --> F(x)L
L --> [+G]
)";
    Grammar g = parseGrammar(text, "t.lsys");
    CHECK(g.hasInterpretation());
    Deriver d(g, DeriveOptions{.steps = 2});
    const ModuleString& s = d.derive();
    CHECK(formatModuleString(s, d.symbols()) == "A(3)");
    CHECK(formatModuleString(d.interpret(s), d.symbols()) == "F(3)[+G]");
  }
  SECTION("homomorphism: is interpretation:, and depth 1 stops after one level") {
    Grammar g = parseGrammar("axiom: A\nhomomorphism: no warnings\nA --> BL\nL --> X\n", "t.lsys");
    Deriver d(g);
    CHECK(formatModuleString(d.interpret(d.derive()), d.symbols()) == "BL");
  }
  SECTION("without interpretation rules interpret() returns the string") {
    Grammar g = parseGrammar("axiom: AB\n", "t.lsys");
    Deriver d(g);
    CHECK(formatModuleString(d.interpret(d.current()), d.symbols()) == "AB");
  }
}

TEST_CASE("Deriver::derive cut symbol %", "[lsystem]") {
  // The `%` stays (the turtle marks the internode it ends as cut); the rest of its branch goes.
  CHECK(deriveText("axiom: A[B%CD]E\n", 0) == "A[B%]E");
  CHECK(deriveText("axiom: A[B%C[D]E]F\n", 0) == "A[B%]F");
  CHECK(deriveText("axiom: AB%CD\n", 0) == "AB%");
  CHECK(deriveText("axiom: A[X]B\nX --> Y%Z\nB --> BB\n", 1) == "A[Y%]BB");
  CHECK(deriveText("axiom: A[X]B\nX --> Y%Z\nB --> BB\n", 2) == "A[Y%]BBBB");
  CHECK(deriveText("axiom: A[X[P]Q]B\nX --> %\n", 1) == "A[%]B");
}

TEST_CASE("Deriver::derive birth steps", "[lsystem]") {
  Grammar g = parseGrammar("axiom: FA\nA --> FA\n", "t.lsys");
  SECTION("off by default") {
    ModuleString s = derive(g, DeriveOptions{.steps = 3});
    CHECK(s.birthSteps.empty());
    CHECK_FALSE(s.hasBirthSteps());
  }
  SECTION("each module keeps the step that created it") {
    Deriver d(g, DeriveOptions{.steps = 3, .trackBirthSteps = true});
    const ModuleString& s = d.derive();
    REQUIRE(s.hasBirthSteps());
    CHECK(formatModuleString(s, d.symbols()) == "FFFFA");
    CHECK(s.birthSteps == std::vector<int32_t>{0, 1, 2, 3, 3});
    CHECK(d.interpret(s).birthSteps == s.birthSteps);
  }
  SECTION("long runs of untouched modules (bulk copies) keep parameters and birth steps") {
    Grammar h = parseGrammar("axiom: F(1)F(2)F(3)F(4)F(5)F(6)F(7)F(8)F(9)A(0)\nA(x) --> F(x)+(x)!A(x+1)\n", "t.lsys");
    Deriver d(h, DeriveOptions{.steps = 3, .trackBirthSteps = true});
    const ModuleString& s = d.derive();
    CHECK(formatModuleString(s, d.symbols()) == "F(1)F(2)F(3)F(4)F(5)F(6)F(7)F(8)F(9)F(0)+(0)!F(1)+(1)!F(2)+(2)!A(3)");
    CHECK(s.birthSteps == std::vector<int32_t>{0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3, 3});
  }
}

TEST_CASE("Deriver::derive module limit", "[lsystem]") {
  SECTION("a deterministic grammar stops before allocating the step that overflows") {
    Grammar g = parseGrammar("axiom: F\nF --> FF\n", "grow.lsys");
    CHECK(errorOf([&] { derive(g, DeriveOptions{.steps = 10, .maxModules = 100}); }) ==
          "grow.lsys:1:1: error: derivation would exceed 100 modules at step 7\n  axiom: F\n  ^");
    CHECK(derive(g, DeriveOptions{.steps = 6, .maxModules = 64}).size() == 64);
  }
  SECTION("a stochastic grammar stops while writing") {
    Grammar g = parseGrammar("axiom: F\nF --> FF : 1\nF --> FFF : 1\n", "grow.lsys");
    std::string msg = errorOf([&] { derive(g, DeriveOptions{.steps = 30, .maxModules = 1000}); });
    CHECK(msg.rfind("grow.lsys:1:1: error: derivation would exceed 1000 modules at step ", 0) == 0);
  }
  SECTION("the error points at 'derivation length:' when the grammar's own length is used") {
    Grammar g = parseGrammar("axiom: F\n  derivation length: 12\nF --> FF\n", "grow.lsys");
    CHECK(errorOf([&] { derive(g, DeriveOptions{.maxModules = 100}); }) ==
          "grow.lsys:2:3: error: derivation would exceed 100 modules at step 7\n    derivation length: 12\n    ^");
    // --steps (or an override of the length) makes the axiom the place to look.
    CHECK(errorOf([&] { derive(g, DeriveOptions{.steps = 9, .maxModules = 100}); }).rfind("grow.lsys:1:1: error: derivation", 0) == 0);
    Grammar h = parseGrammar("axiom: F\nderivation length: 12\nF --> FF\n", "grow.lsys", GrammarOverrides{.derivationLength = 9});
    CHECK(errorOf([&] { derive(h, DeriveOptions{.maxModules = 100}); }).rfind("grow.lsys:1:1: error: derivation", 0) == 0);
  }
  SECTION("an axiom longer than the limit fails at step 0") {
    Grammar g = parseGrammar("axiom: FFFF\n", "long.lsys");
    CHECK(errorOf([&] { derive(g, DeriveOptions{.maxModules = 3}); }) ==
          "long.lsys:1:1: error: derivation would exceed 3 modules at step 0\n  axiom: FFFF\n  ^");
  }
  SECTION("the default limit is 50 million") { CHECK(DeriveOptions{}.maxModules == 50'000'000); }
}

TEST_CASE("Deriver::derive non-finite parameters", "[lsystem]") {
  const char* text = "axiom: A(1)\nA(x) --> A(x-1)B(1/x)\n";
  Grammar g = parseGrammar(text, "nan.lsys");
  CHECK(errorOf([&] { derive(g, DeriveOptions{.steps = 3}); }) ==
        "nan.lsys:2:1: error: non-finite parameter value (inf) in production 'A(x)' at step 2 (parameter 1 of 'B')\n"
        "  A(x) --> A(x-1)B(1/x)\n"
        "  ^");
  Grammar h = parseGrammar("axiom: A(-1)\n  A(x) --> B(sqrt(x))\n", "nan.lsys");
  CHECK(errorOf([&] { derive(h, DeriveOptions{.steps = 1}); }) ==
        "nan.lsys:2:3: error: non-finite parameter value (nan) in production 'A(x)' at step 1 (parameter 1 of 'B')\n"
        "    A(x) --> B(sqrt(x))\n"
        "    ^");
}

TEST_CASE("formatModuleString", "[lsystem]") {
  SymbolTable t;
  ModuleString s = parseModuleString("F(1.5)[+(25.7)A(2,3)]Apex", t);
  SECTION("round trip in grammar notation") { CHECK(formatModuleString(s, t) == "F(1.5)[+(25.7)A(2,3)]Apex"); }
  SECTION("a space separates a multi-character name from a following letter") {
    SymbolTable u;
    u.intern("Apex");
    ModuleString m = parseModuleString("Apex Apex A", u);
    CHECK(m.size() == 3);
    CHECK(formatModuleString(m, u) == "Apex Apex A");
  }
  SECTION("wrapping at module boundaries") {
    SymbolTable u;
    ModuleString m = parseModuleString("FFFFFFFFFF", u);
    CHECK(formatModuleString(m, u, FormatOptions{.wrapColumn = 4}) == "FFFF\nFFFF\nFF");
  }
  SECTION("countSymbol") {
    CHECK(countSymbol(s, t, "A") == 2);  // undeclared, "Apex" is the four modules A p e x
    CHECK(s.size() == 9);
    CHECK(countSymbol(s, t, "nothing") == 0);
  }
}

TEST_CASE("Grammar shipped grammars parse and derive", "[lsystem]") {
  namespace fs = std::filesystem;
  fs::path dir = fs::path(SPRIG_SOURCE_DIR) / "grammars";
  if (!fs::exists(dir)) return;
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().extension() != ".lsys") continue;
    INFO(entry.path().string());
    Grammar g = loadGrammar(entry.path().string());
    Deriver d(g, DeriveOptions{.maxModules = 20'000'000});
    CHECK(d.derive().size() > 0);
    ++count;
  }
  CHECK(count > 0);
}
