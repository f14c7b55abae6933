/// Fuzz target: texture loading (core/image.h readImage, through OpenImageIO). The input is
/// written to a file of this process (OIIO reads files; the extension is chosen by the
/// first byte among the formats textures use) and read back. OpenImageIO itself is not
/// instrumented: this exercises Sprig's checks around it (sizes, channels, the failure
/// paths) and catches crashes and leaks in either.
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>

#include "core/image.h"
#include "fuzz/fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > sprig::fuzz::kMaxInput) return 0;
  const char* exts[] = {".png", ".jpg", ".exr", ".tif", ".hdr", ".ppm"};
  const std::string path = "/tmp/sprig-fuzz-image-" + std::to_string(getpid()) + exts[data[0] % 6];
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
  }
  try {
    sprig::readImage(path);
  } catch (const sprig::ImageReadError&) {
  }
  std::remove(path.c_str());
  return 0;
}
