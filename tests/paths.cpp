#include "tests/paths.h"

namespace sprig::test {
const char* sourceDir() { return SPRIG_PATHS_SOURCE_DIR; }
const char* binaryDir() { return SPRIG_PATHS_BINARY_DIR; }
}  // namespace sprig::test
