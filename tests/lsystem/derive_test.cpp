#include <catch2/catch.hpp>

#include "core/atomic_file.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

std::string asset(const std::string& name) { return std::string(SPRIG_SOURCE_DIR) + "/tests/assets/lsystem/" + name; }

std::string deriveText(const std::string& text, int steps) {
  Grammar g = parseGrammar(text, "t.lsys");
  DeriveOptions opt;
  opt.steps = steps;
  Deriver d(g, opt);
  return formatModuleString(d.derive(), d.symbols());
}

}  // namespace

TEST_CASE("Deriver::derive ABOP 1.24a", "[lsystem]") {
  Grammar g = loadGrammar(asset("abop_1_24a.lsys"));
  ModuleString s = derive(g);
  CHECK(s.size() == 7811);
  CHECK(countSymbol(s, g.symbols(), "F") == 3125);
  CHECK(g.angleDeg().value() == 25.7);
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
}
