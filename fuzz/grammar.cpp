/// Fuzz target: the grammar parser (lsystem::parseGrammar) on any bytes, in both notations:
/// Sprig's (`.lsys`) and cpfg's (`.l`: tab-continued lines, cpfg's precedence of `^`).
#include "fuzz/fuzz.h"
#include "lsystem/grammar.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  for (const char* name : {"fuzz.lsys", "fuzz.l"}) {
    try {
      sprig::lsystem::parseGrammar(sprig::fuzz::text(data, size), name);
    } catch (const sprig::InputError&) {
    }
  }
  return 0;
}
