#pragma once
/// Bark along a branch bark ridge: compressed, darker bark on the crest and folds of bunched
/// bark that run parallel to the seam ("BlobTree Trees" §5: "the deformed fields resulting
/// from PCM may be used as input to a procedural texturing algorithm to modify the texture on
/// the branch bark ridge, where a discolouration is observed").
///
/// The input is the PCM contact c in [0, 1] (blobtree::Attributes::contact: 0 at the outer
/// edge of the propagation band, 1 on the seam). The folds are level sets of c, so they
/// follow the ridge around the branch, and their phase φ(c) = lines·c^1.5 (+ a wander drawn
/// from noise at the world point) crowds them toward the crest, where the bark is pushed
/// together. The relief is a height profile H(c) in units of the band's width (1/|∇c|): a
/// rounded crest smoothstep(c) with the folds cut into it. Measured in the band's width, the
/// world slope along ∇c is dH/dc itself, whatever the branch's size, so the crest reads alike
/// on a twig and on the trunk; a shader tilts its normal by it.

#include <cstdint>

#include "core/types.h"
#include "textures/noise.h"

namespace sprig::textures {

/// How the bark of a branch bark ridge looks; the defaults change nothing.
struct RidgeOptions {
  double darkening = 0.0;  ///< crest darkening: colour × (1 − darkening·c³), in [0, 1]
  int lines = 0;           ///< bark folds across the band, parallel to the seam (0: none)
  double relief = 0.0;     ///< slope of the crest's flanks at c = 1/2 is 1.5·relief (0: flat)
  double wanderScale = 20.0;  ///< frequency of the folds' wander along the ridge, per world unit
  uint64_t seed = 0;
};

/// The ridge shading of RidgeOptions. Immutable; thread-safe; a pure function of its inputs.
class RidgeShade {
 public:
  /// No ridge: changes nothing.
  RidgeShade() : RidgeShade(RidgeOptions{}) {}
  explicit RidgeShade(const RidgeOptions& options) : options_(options), noise_(options.seed) {}
  const RidgeOptions& options() const { return options_; }
  /// True when the ridge changes neither colour nor shading.
  bool none() const { return !(options_.darkening > 0) && !(options_.relief > 0); }
  /// How much darker the bark is at contact c and world point p, in [0, 1]: the colour is
  /// multiplied by 1 − darkness. Cost: one noise lookup when lines > 0.
  double darkness(double contact, const Vec3& p) const;
  /// The ridge's surface slope toward the seam (rise per world unit along ∇c): relief·dH/dc.
  /// Cost: one noise lookup and two profile evaluations.
  double slope(double contact, const Vec3& p) const;
  /// The unit shading normal: n tilted away from the seam by the ridge's slope, given the
  /// contact c and its gradient (blobtree::Attributes::contactGradient). n when relief is 0
  /// or the gradient has no tangential part.
  Vec3 shadingNormal(const Vec3& n, double contact, const Vec3& contactGradient, const Vec3& p) const;

 private:
  double fold(double contact, double wander) const;
  double wander(const Vec3& p) const;

  RidgeOptions options_;
  PerlinNoise noise_;
};

}  // namespace sprig::textures
