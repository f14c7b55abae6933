#pragma once
/// Private: tapes pruned to a box (libfive's per-region tape simplification).
///
/// A pruned tape keeps, for one surface cell (or any box), only the nodes whose support
/// reaches the box, and drops operators that become identities there: a sum blend, union or
/// super-elliptic blend with one non-negative child is that child; a difference whose
/// subtrahend cannot reach the box is its minuend when the minuend's interval over the box
/// lies in [0, 1] (else the subtrahend becomes an empty node, F = 0); an intersection,
/// negative node or warp whose operand cannot reach is zero and is dropped with it. A PCM
/// node is kept even with one child ((f + d) − d is not f in floating point). The pruning
/// is exact: at points in the box the pruned tape evaluates the same terms as the full one,
/// in the same order wherever the full tape's child order does not depend on the batch
/// (nodes without a point grid, and boxes inside one grid cell), so values agree bit for
/// bit there and to rounding of the sums elsewhere.
///
/// Pruning runs in two steps so identical pruned tapes of neighbouring cells are stored
/// once: pruneKey writes a canonical key (the kept base nodes in pre-order with their child
/// counts), buildPruned turns a key into a tape that shares the base's primitives and
/// parameters.

#include "blobtree/detail/tape.h"

#include <memory>
#include <span>
#include <vector>

namespace sprig::blobtree::detail {

/// The key word of an empty (F = 0) operand.
inline constexpr uint32_t kPrunedEmpty = 0xffffffffu;

/// Appends to key the pruned form of the base tape's root over box (box should enclose the
/// points evaluated later with a margin for rounding). Returns false (key unchanged) when
/// no node reaches box: F = 0 there.
bool pruneKey(const Tape& T, const Box3& box, std::vector<uint32_t>& key);

/// The tape a key from pruneKey describes; it shares base's primitives and parameters.
std::shared_ptr<const Tape> buildPruned(const std::shared_ptr<const Tape>& base, std::span<const uint32_t> key);

}  // namespace sprig::blobtree::detail
