#pragma once
/// Private: the point value evaluator of the tape.

#include "blobtree/detail/tape.h"

namespace sprig::blobtree::detail {

/// F of tape node ni at p. cull: skip children whose support box misses p (through the
/// node's point grid); false visits every node (the brute-force baseline).
float evalV(const Tape& T, uint32_t ni, Vec3 p, bool cull);

}  // namespace sprig::blobtree::detail
