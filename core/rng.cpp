#include "core/rng.h"

#include <cmath>

namespace sprig {

double Rng::normal(double mean, double sd) {
  // 1 - uniform() lies in (0, 1], so the log is finite.
  double u1 = 1.0 - uniform();
  double u2 = uniform();
  double r = std::sqrt(-2.0 * std::log(u1));
  return mean + sd * r * std::cos(2.0 * 3.14159265358979323846 * u2);
}

}  // namespace sprig
