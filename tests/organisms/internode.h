#pragma once
/// Hand-built skeletons for the organisms tests.

#include "lsystem/skeleton.h"

namespace sprig::test {

/// An internode from a to b with radii r0 (at a) and r1 (at b), the parent index, the
/// branch order and the cut mark; the other fields keep their defaults.
inline lsystem::Internode seg(DVec3 a, DVec3 b, double r0, double r1, int parent, int order, bool cut = false) {
  return {.start = a, .end = b, .baseRadius = r0, .tipRadius = r1, .parent = parent, .order = order, .cut = cut};
}

}  // namespace sprig::test
