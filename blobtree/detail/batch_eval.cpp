#include "blobtree/detail/batch_eval.h"

#include "blobtree/detail/traverse.h"

#include <immintrin.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

// The batch walk is compiled twice from batch_walk.inc: for the build's baseline
// (x86-64-v2, SSE4.2) and for AVX2, and evalBatch picks one at run time. Why this is safe:
//
// - Only Sprig's own code is compiled for AVX2: the region's pragma comes after every
//   #include, so the inline functions and templates of the headers (glm, the standard
//   library, traverse.h) keep the baseline target. GCC and clang take a function's target
//   from where it is defined, not where it is instantiated, and both inline a baseline
//   function into an AVX2 caller (the reverse is refused). So no COMDAT copy of a header
//   function is AVX2 code that the linker could pick for the baseline path (SIGILL on an
//   older CPU); scripts/check-avx2-region.sh checks the object for it: no AVX instruction
//   in any function outside avx2::.
// - Everything in the region is in a namespace of internal linkage (avx2:: inside the
//   anonymous namespace), so it shares no symbol with the baseline copy (no ODR clash) and
//   runs only when evalBatch has seen AVX2 on the CPU.
// - The same bits: the walk is written on lanes.inc's F8, whose every operation is one
//   correctly rounded IEEE operation per lane in either form; the region enables "avx2"
//   without "fma" and this file is compiled with -ffp-contract=off, so nothing is fused;
//   the scalar code (the Ricci blend's pow, the other warps) makes the same libm calls.
//   test_blobtree "evalBatch: the AVX2 walk" compares the two walks' bits.
#if defined(__clang__)
#define SPRIG_AVX2_BEGIN _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define SPRIG_AVX2_END _Pragma("clang attribute pop")
#elif defined(__GNUC__)
#define SPRIG_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define SPRIG_AVX2_END _Pragma("GCC pop_options")
#endif

namespace sprig::blobtree::detail {

namespace {

namespace baseline {
#define SPRIG_LANES_AVX2 0
#include "blobtree/detail/lanes.inc"
#include "blobtree/detail/batch_walk.inc"
#undef SPRIG_LANES_AVX2
}  // namespace baseline

SPRIG_AVX2_BEGIN
namespace avx2 {
#define SPRIG_LANES_AVX2 1
#include "blobtree/detail/lanes.inc"
#include "blobtree/detail/batch_walk.inc"
#undef SPRIG_LANES_AVX2
}  // namespace avx2
SPRIG_AVX2_END

/// The walk evalBatch uses: AVX2 when the CPU has it, unless SPRIG_BATCH_ISA=baseline.
BatchIsa startupIsa() {
  const char* env = std::getenv("SPRIG_BATCH_ISA");
  if (env && std::strcmp(env, "baseline") == 0) return BatchIsa::Baseline;
  return batchIsaSupported(BatchIsa::Avx2) ? BatchIsa::Avx2 : BatchIsa::Baseline;
}

std::atomic<BatchIsa> gIsa{startupIsa()};

}  // namespace

bool batchIsaSupported(BatchIsa isa) {
  if (isa == BatchIsa::Baseline) return true;
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

BatchIsa batchIsa() { return gIsa.load(std::memory_order_relaxed); }

BatchIsa setBatchIsa(BatchIsa isa) {
  if (!batchIsaSupported(isa)) isa = BatchIsa::Baseline;
  return gIsa.exchange(isa);
}

void evalBatch(const Tape& T, std::span<const Vec3> points, std::span<float> out) {
  if (batchIsa() == BatchIsa::Avx2) avx2::evalBlocks(T, points, out);
  else baseline::evalBlocks(T, points, out);
}

}  // namespace sprig::blobtree::detail
