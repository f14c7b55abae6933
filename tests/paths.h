#pragma once
/// Where the checkout and the build folder are, for tests that read shipped files or write
/// scratch files. Only tests/paths.cpp is compiled with the absolute paths, so no test
/// file's object depends on where the checkout lies and the compiler cache shares them
/// between checkouts (worktrees, CI's clone, the fresh-machine test's /root/sprig).
namespace sprig::test {
const char* sourceDir();  ///< the checkout (CMAKE_SOURCE_DIR)
const char* binaryDir();  ///< the build folder (CMAKE_BINARY_DIR)
}  // namespace sprig::test

#define SPRIG_SOURCE_DIR (::sprig::test::sourceDir())
#define SPRIG_BINARY_DIR (::sprig::test::binaryDir())
