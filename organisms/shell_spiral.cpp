#include "organisms/shell_spiral.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace sprig::organisms {

double HelicoSpiral::radius(double thetaDeg) const { return r0 * std::pow(lambda, thetaDeg / 360.0); }

double HelicoSpiral::height(double thetaDeg) const {
  const double beta = radians(betaDeg);
  return radius(thetaDeg) * std::cos(beta) / std::sin(beta);
}

double HelicoSpiral::sizeRatio() const { return (lambda - 1.0) / ((lambda + 1.0) * std::sin(radians(betaDeg))); }

double HelicoSpiral::curveSize(double thetaDeg) const { return radius(thetaDeg) * sizeRatio(); }

DVec3 HelicoSpiral::point(double thetaDeg) const {
  const double t = radians(thetaDeg);
  const double r = radius(thetaDeg);
  // Right-hand rotation about +y maps +x to (cos θ, 0, −sin θ).
  return {r * std::cos(t), height(thetaDeg), -r * std::sin(t)};
}

DVec3 HelicoSpiral::tangent(double thetaDeg) const {
  // d/dθ of point(): R' = R·ln λ / 360 per degree; the common factor R drops out.
  const double t = radians(thetaDeg);
  const double k = std::log(lambda) / (2.0 * kPi);  // R'/R per radian
  const double beta = radians(betaDeg);
  const double cotB = std::cos(beta) / std::sin(beta);
  DVec3 d{k * std::cos(t) - std::sin(t), k * cotB, -k * std::sin(t) - std::cos(t)};
  return glm::normalize(d);
}

glm::dmat4 HelicoSpiral::shellFromGenerating(double thetaDeg) const { return shellFromGenerating(thetaDeg, 1.0); }

glm::dmat4 HelicoSpiral::shellFromGenerating(double thetaDeg, double scale) const {
  // Eq. 8, applied right to left: scale by D, translate by (R, H, 0), rotate by θ about y.
  const double d = curveSize(thetaDeg) * scale;
  glm::dmat4 m = glm::rotate(glm::dmat4(1.0), radians(thetaDeg), glm::dvec3(0, 1, 0));
  m = glm::translate(m, glm::dvec3(radius(thetaDeg), height(thetaDeg), 0.0));
  return glm::scale(m, glm::dvec3(d));
}

double HelicoSpiral::angleAtRadius(double r) const { return 360.0 * std::log(r / r0) / std::log(lambda); }

}  // namespace sprig::organisms
