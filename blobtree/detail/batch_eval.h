#pragma once
/// Private: the batch evaluator of the tape: F over blocks of points, node by node over
/// structure-of-arrays coordinates, culled by the block's bounding box, primitives in SIMD
/// lanes (SSE, or AVX2 when the CPU has it: the same bits either way).

#include "blobtree/detail/tape.h"

#include <span>

namespace sprig::blobtree::detail {

/// out[i] = F(points[i]) of the tape's root, in blocks of 256 points (out.size() >= points.size()).
void evalBatch(const Tape& T, std::span<const Vec3> points, std::span<float> out);

/// The instruction sets evalBatch can walk in: the build's baseline (x86-64-v2: SSE4.2)
/// and AVX2. Both give the same bits.
enum class BatchIsa { Baseline, Avx2 };
/// Whether this CPU runs isa (Baseline always).
bool batchIsaSupported(BatchIsa isa);
/// The walk evalBatch uses: AVX2 when the CPU has it, unless the environment variable
/// SPRIG_BATCH_ISA is "baseline" at start-up.
BatchIsa batchIsa();
/// Makes evalBatch use isa from now on (Baseline when the CPU lacks it); returns the
/// previous one. For tests and comparisons; not to be called while batches run.
BatchIsa setBatchIsa(BatchIsa isa);

}  // namespace sprig::blobtree::detail
