#pragma once
/// Hand-built skeletons for the organisms tests.

#include <cmath>

#include "lsystem/skeleton.h"

namespace sprig::test {

/// An internode from a to b with radii r0 (at a) and r1 (at b), the parent index, the
/// branch order and the cut mark; the other fields keep their defaults.
inline lsystem::Internode seg(DVec3 a, DVec3 b, double r0, double r1, int parent, int order, bool cut = false) {
  return {.start = a, .end = b, .baseRadius = r0, .tipRadius = r1, .parent = parent, .order = order, .cut = cut};
}

/// A trunk of four internodes up +Y with a lateral of two internodes at each of its upper
/// three joints, and a leaf polygon on each lateral's tip (the wind tests' tree).
inline lsystem::Skeleton windTree() {
  lsystem::Skeleton sk;
  for (int i = 0; i < 4; ++i) sk.internodes.push_back(seg({0, i, 0}, {0, i + 1, 0}, 0.2 - 0.04 * i, 0.16 - 0.04 * i, i - 1, 0));
  for (int j = 1; j < 4; ++j) {
    const DVec3 p(0, j, 0), d = glm::normalize(DVec3(std::cos(2.0 * j), 1.0, std::sin(2.0 * j)));
    const int first = static_cast<int>(sk.internodes.size());
    sk.internodes.push_back(seg(p, p + 0.5 * d, 0.05, 0.04, j - 1, 1));
    sk.internodes.push_back(seg(p + 0.5 * d, p + d, 0.04, 0.03, first, 1));
    lsystem::Organ leaf;
    leaf.points = {p + d, p + d + DVec3(0.1, 0.05, 0), p + d + DVec3(0, 0.2, 0), p + d + DVec3(-0.1, 0.05, 0)};
    leaf.internode = first + 1;
    sk.organs.push_back(leaf);
  }
  return sk;
}

}  // namespace sprig::test
