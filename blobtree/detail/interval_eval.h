#pragma once
/// Private: the interval evaluators of the tape: bounds of F and of its Lipschitz
/// constant over an axis-aligned box.

#include "blobtree/detail/tape.h"

namespace sprig::blobtree::detail {

/// Sound interval of F of tape node ni over box.
Interval evalI(const Tape& T, uint32_t ni, const Box3& box);
/// Local Lipschitz bound of tape node ni over box, never above the node's global bound.
float evalL(const Tape& T, uint32_t ni, const Box3& box);
/// The child-space box covering the preimage of world box under warp node n (Transform,
/// Bend, Twist, Taper; box itself for other kinds).
Box3 localBoxOf(const TNode& n, const Tape& T, const Box3& box);

}  // namespace sprig::blobtree::detail
