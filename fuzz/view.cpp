/// Fuzz target: cpfg's view file reader (lsystem::parseViewFile) and the turtle settings it
/// makes, on any bytes. The input is read as fuzz.v in a fresh sandbox folder that holds
/// only special files: `fifo` (a FIFO no one writes to) and `folder` (an empty folder). The
/// files its lines name (surface, function, function set, curve, contour files, texture
/// images) are therefore missing, or one of those two, which every reader must refuse
/// without opening (a FIFO would block the run forever); nothing outside the sandbox is
/// read (an image of the checkout could take a gigabyte of floats).
#include "fuzz/fuzz.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "lsystem/view_file.h"

namespace {

/// The sandbox folder: a FIFO no one writes to and an empty folder.
const std::string& sandbox() {
  return sprig::fuzz::sandboxFolder("view", [](const std::string& dir) {
    ::mkfifo((dir + "/fifo").c_str(), 0600);
    ::mkdir((dir + "/folder").c_str(), 0700);
  });
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    const sprig::lsystem::ViewFile v =
        sprig::lsystem::parseViewFile(std::string(sprig::fuzz::text(data, size)), sandbox() + "/fuzz.v");
    (void)sprig::lsystem::cpfgTurtleSettings(&v, {});
  } catch (const sprig::InputError&) {
  }
  return 0;
}
