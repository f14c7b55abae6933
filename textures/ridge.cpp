#include "textures/ridge.h"

#include <algorithm>
#include <cmath>

namespace sprig::textures {

namespace {

/// Depth of the folds in H (units of the band's width): slopes of about ±0.3·relief.
constexpr double kFoldDepth = 0.05;

}  // namespace

double RidgeShade::wander(const Vec3& p) const {
  if (options_.lines <= 0) return 0.0;
  return 0.35 * noise_(DVec3(p) * options_.wanderScale + DVec3(0.37, 0.11, 0.73));
}

/// A fold's profile at contact c: 1 in the middle of a fold, 0 between folds; the phase
/// lines·c^1.5 runs faster toward c = 1, so the folds bunch up at the crest.
double RidgeShade::fold(double c, double wander) const {
  if (options_.lines <= 0 || !(c > 0)) return 0.0;
  const double phase = options_.lines * std::pow(c, 1.5) + wander;
  return std::pow(0.5 + 0.5 * std::cos(2 * kPi * phase), 6.0);
}

double RidgeShade::darkness(double contact, const Vec3& p) const {
  const double c = std::clamp(contact, 0.0, 1.0);
  if (!(c > 0) || !(options_.darkening > 0)) return 0.0;
  const double crest = c * c * c;
  const double folds = c * fold(c, wander(p));
  return std::clamp(options_.darkening * (crest + 0.8 * folds * (1 - crest)), 0.0, 1.0);
}

double RidgeShade::slope(double contact, const Vec3& p) const {
  const double c = std::clamp(contact, 0.0, 1.0);
  if (!(options_.relief > 0) || !(c > 0) || !(c < 1)) return 0.0;
  // H(c) = smoothstep(c) − kFoldDepth·c·fold(c)/rate, the folds scaled by the phase's rate
  // dφ/dc so their slope stays about the same as they crowd together.
  const double w = wander(p);
  auto H = [&](double x) {
    const double rate = std::max(1.0, 1.5 * options_.lines * std::sqrt(std::max(x, 0.0)));
    return x * x * (3 - 2 * x) - kFoldDepth * x * fold(x, w) * (options_.lines > 0 ? 2 * kPi / rate : 0.0);
  };
  const double h = 1e-3;
  const double lo = std::max(0.0, c - h), hi = std::min(1.0, c + h);
  return options_.relief * (H(hi) - H(lo)) / (hi - lo);
}

Vec3 RidgeShade::shadingNormal(const Vec3& n, double contact, const Vec3& contactGradient, const Vec3& p) const {
  if (!(options_.relief > 0)) return n;
  const Vec3 gt = contactGradient - glm::dot(contactGradient, n) * n;  // along the surface, toward the seam
  const float len = glm::length(gt);
  if (!(len > 1e-5f * glm::length(contactGradient))) return n;  // (rounding left of a normal gradient)
  // The slope, capped so the normal never turns past the surface.
  const double s = std::clamp(slope(contact, p), -4.0, 4.0);
  const Vec3 tilted = n - static_cast<float>(s) * (gt / len);
  const float tl = glm::length(tilted);
  return tl > 0 ? tilted / tl : n;
}

}  // namespace sprig::textures
