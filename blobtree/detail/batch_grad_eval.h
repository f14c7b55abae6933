#pragma once
/// Private: the batched value-and-gradient evaluator of the tape: F and ∇F over blocks of
/// points, node by node over structure-of-arrays coordinates, culled by the block's
/// bounding box. The formulas are gradient_eval's (evalS) without the attributes, so the
/// results agree with CompiledBlob::sample to the rounding of sums whose terms come in a
/// different child order.

#include "blobtree/detail/tape.h"

#include <span>

namespace sprig::blobtree::detail {

/// value[i] = F(points[i]) and gradient[i] = ∇F(points[i]) of the tape's root, in blocks
/// of 64 points (value and gradient at least points.size() long).
void evalBatchGradient(const Tape& T, std::span<const Vec3> points, std::span<float> value, std::span<Vec3> gradient);

}  // namespace sprig::blobtree::detail
