/// Fuzz target: cpfg's view file reader (lsystem::parseViewFile) and the turtle settings it
/// makes, on any bytes. The input is read as /sprig-fuzz-sandbox/fuzz.v, a folder that does
/// not exist, so the files its lines name (surface, function, curve, contour files, texture
/// images) are missing: nothing outside the input is read (an image of the checkout could
/// take a gigabyte of floats).
#include "fuzz/fuzz.h"
#include <string>

#include "lsystem/view_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    const sprig::lsystem::ViewFile v = sprig::lsystem::parseViewFile(std::string(sprig::fuzz::text(data, size)),
                                                                        "/sprig-fuzz-sandbox/fuzz.v");
    (void)sprig::lsystem::cpfgTurtleSettings(&v, {});
  } catch (const sprig::InputError&) {
  }
  return 0;
}
