#pragma once
/// Private: the batch evaluator of the tape: F over blocks of points, node by node over
/// structure-of-arrays coordinates, culled by the block's bounding box, primitives in SSE.

#include "blobtree/detail/tape.h"

#include <span>

namespace sprig::blobtree::detail {

/// out[i] = F(points[i]) of the tape's root, in blocks of 256 points (out.size() >= points.size()).
void evalBatch(const Tape& T, std::span<const Vec3> points, std::span<float> out);

}  // namespace sprig::blobtree::detail
