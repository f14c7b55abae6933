/// Fuzz target: cpfg's function file reader (lsystem::CpfgFunction::parse, both formats) and
/// the evaluation of the function it makes, on any bytes.
#include "fuzz/fuzz.h"
#include <string>

#include "core/diagnostics.h"
#include "lsystem/cpfg_function.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    const sprig::lsystem::CpfgFunction f =
        sprig::lsystem::CpfgFunction::parse(std::string(sprig::fuzz::text(data, size)), "fuzz.func", -1);
    for (double x : {0.0, 0.25, 0.5, 1.0}) (void)f.value(x);
  } catch (const sprig::InputError&) {
  }
  return 0;
}
