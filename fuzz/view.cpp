/// Fuzz target: cpfg's view file reader (lsystem::parseViewFile) and the turtle settings it
/// makes, on any bytes.
#include "fuzz/fuzz.h"
#include <string>

#include "lsystem/view_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    const sprig::lsystem::ViewFile v = sprig::lsystem::parseViewFile(std::string(sprig::fuzz::text(data, size)), "fuzz.v");
    (void)sprig::lsystem::cpfgTurtleSettings(&v, {});
  } catch (const sprig::InputError&) {
  }
  return 0;
}
