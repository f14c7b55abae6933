#pragma once
/// The logarithmic helico-spiral along which a shell's generating surface is swept.
///
/// Galbraith, Prusinkiewicz, Wyvill, "Modeling a Murex cabritii sea shell with a structured
/// implicit surface modeler", Section 2.1 and Eq. 8. Shell coordinates: the shell axis is y;
/// the spiral point at angle θ is r(Y, θ)·(R(θ), H(θ), 0) with the right-hand rule, so at
/// θ = 0 it lies on +x and it turns towards −z. Angles are in degrees throughout, as in the
/// paper. Double precision: a seven-whorl shell spans a factor λ⁷ ≈ 6 in size and its
/// placements are composed with further transforms.

#include <glm/mat4x4.hpp>

#include "core/types.h"

namespace sprig::organisms {

/// R(θ) = R₀·λ^(θ/360°) (Eq. 1), H(θ) = R(θ)·cot β (Eq. 2), and the generating-curve size
/// D(θ) = R(θ)·(λ−1)/((λ+1)·sin β) (Eq. 3, with sin β dividing: consecutive whorls of circles
/// of radius D are exactly tangent).
struct HelicoSpiral {
  double lambda = 1.3;   ///< ratio of radii one full turn (360°) apart; > 1
  double betaDeg = 22.5; ///< angle between the shell axis and the line through successive whorls; in (0°, 90°]
  double r0 = 0.2;       ///< R at θ = 0; > 0

  /// Distance of the spiral point from the shell axis (Eq. 1).
  double radius(double thetaDeg) const;
  /// Height of the spiral point along the shell axis (Eq. 2).
  double height(double thetaDeg) const;
  /// Radius of the circular generating curve that makes consecutive whorls tangent (Eq. 3).
  double curveSize(double thetaDeg) const;
  /// D(θ)/R(θ) = (λ−1)/((λ+1)·sin β); 0.341 for the Murex parameters.
  double sizeRatio() const;
  /// The spiral point in shell coordinates: r(Y, θ)·(R, H, 0).
  DVec3 point(double thetaDeg) const;
  /// Unit tangent of the spiral at θ (direction of growth).
  DVec3 tangent(double thetaDeg) const;
  /// P(·, θ) of Eq. 8 as a matrix: shellFromGenerating = r(Y, θ)·t(R, H, 0)·s(D).
  /// The generating surface is modelled in a unit frame: x points away from the axis,
  /// y along the axis, the curve lies in the xy plane, and size 1 becomes D(θ).
  glm::dmat4 shellFromGenerating(double thetaDeg) const;
  /// Same as shellFromGenerating with an extra uniform scale `scale` applied to D.
  glm::dmat4 shellFromGenerating(double thetaDeg, double scale) const;
  /// Angle θ at which R(θ) = r (inverse of Eq. 1).
  double angleAtRadius(double r) const;
};

}  // namespace sprig::organisms
