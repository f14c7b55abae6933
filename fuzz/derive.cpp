/// Fuzz target: a parsed grammar derived for at most 4 steps under a 20,000-module limit,
/// then read by the turtle into a skeleton.
#include <algorithm>

#include "fuzz/fuzz.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sprig::lsystem;
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    Grammar g = parseGrammar(sprig::fuzz::text(data, size), "fuzz.lsys");
    DeriveOptions o;
    o.steps = std::min(g.derivationLength(), 4);
    o.maxModules = 20'000;
    o.trackBirthSteps = true;
    ModuleString s = derive(g, o);
    interpret(s, g.symbols());
  } catch (const sprig::InputError&) {
  }
  return 0;
}
