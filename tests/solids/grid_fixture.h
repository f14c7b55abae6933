#pragma once
/// The cubic grid of the solids tests: [-halfSize, halfSize]³ at the given cell.

#include <cmath>

#include "solids/solid.h"

namespace sprig::test {

inline solids::Grid gridAround(double halfSize, double cell) {
  solids::Grid g;
  g.cell = cell;
  const int n = int(std::ceil(2 * halfSize / cell));
  g.cells = {n, n, n};
  g.origin = DVec3(-halfSize);
  return g;
}

}  // namespace sprig::test
