/// The entry point of libsprig_backends.so (backends/backends.h): the only symbol it exports.

#include "backends/backends.h"

extern "C" __attribute__((visibility("default"))) const sprig::backends::Backends* sprig_backends() {
  using namespace sprig::backends;
  static const Backends all{kBackendsVersion, &oiioImage(), &oiioTexture(), &vdbVolume(), &vdbMeshDistance()};
  return &all;
}
