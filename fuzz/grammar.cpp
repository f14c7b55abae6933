/// Fuzz target: the grammar parser (lsystem::parseGrammar) on any bytes.
#include "fuzz/fuzz.h"
#include "lsystem/grammar.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    sprig::lsystem::parseGrammar(sprig::fuzz::text(data, size), "fuzz.lsys");
  } catch (const sprig::InputError&) {
  }
  return 0;
}
