/// Fuzz target: lsystem::Expression (compile, then evaluate at a few points).
#include "fuzz/fuzz.h"
#include "lsystem/expression.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 4096) return 0;
  try {
    auto e = sprig::lsystem::Expression::compile(sprig::fuzz::text(data, size), {"t", "x"}, sprig::SourceLoc{"fuzz", 1, 1});
    volatile double sum = e({0.0, 1.0}) + e({0.5, -2.0}) + e({1e300, 1e-300});
    (void)sum;
  } catch (const sprig::InputError&) {
  }
  return 0;
}
