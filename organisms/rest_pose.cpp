#include "organisms/rest_pose.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

namespace sprig::organisms {

DVec3 volumeCentroid(const Mesh& mesh) {
  if (mesh.positions.empty()) return DVec3(0.0);
  DVec3 mean(0.0);
  for (const Vec3& p : mesh.positions) mean += DVec3(p);
  mean /= double(mesh.positions.size());
  // Signed tetrahedra from the vertex mean (not the origin: less cancellation far away).
  double volume = 0.0;
  DVec3 moment(0.0);
  for (const auto& t : mesh.triangles) {
    const DVec3 a = DVec3(mesh.positions[t.x]) - mean, b = DVec3(mesh.positions[t.y]) - mean,
                c = DVec3(mesh.positions[t.z]) - mean;
    const double v = glm::dot(a, glm::cross(b, c)) / 6.0;
    volume += v;
    moment += v * (a + b + c) / 4.0;
  }
  if (!(std::abs(volume) > 0.0) || !std::isfinite(volume)) return mean;
  return mean + moment / volume;
}

double restingHeight(std::span<const Vec3> points, const DVec3& centre, const DVec3& up) {
  double lowest = std::numeric_limits<double>::infinity();
  for (const Vec3& p : points) lowest = std::min(lowest, glm::dot(DVec3(p), up));
  return glm::dot(centre, up) - lowest;
}

namespace {

/// Two unit vectors perpendicular to u and to each other.
std::array<DVec3, 2> tangents(const DVec3& u) {
  const DVec3 seed = std::abs(u.x) < 0.6 ? DVec3(1, 0, 0) : DVec3(0, 1, 0);
  const DVec3 t1 = glm::normalize(glm::cross(u, seed));
  return {t1, glm::cross(u, t1)};
}

}  // namespace

DVec3 restingUp(std::span<const Vec3> points, const DVec3& centre, const DVec3& upGuess) {
  // Steps of 0.05 rad (2.9 degrees) roll the body as it rolls: a larger first step could
  // jump over the ridge between two stable poses into the farther one.
  constexpr double kFirstStep = 0.05, kLastStep = 1e-6;
  if (points.empty() || !(glm::length(upGuess) > 0.0)) throw std::invalid_argument("restingUp: no points or a zero guess");
  DVec3 up = glm::normalize(upGuess);
  double best = restingHeight(points, centre, up);
  for (double step = kFirstStep; step > kLastStep;) {
    const auto [t1, t2] = tangents(up);
    DVec3 bestTrial = up;
    double bestTrialHeight = best;
    for (int k = 0; k < 8; ++k) {  // the eight compass directions in the tangent plane
      const double a = k * (3.14159265358979323846 / 4.0);
      const DVec3 trial = glm::normalize(up + step * (std::cos(a) * t1 + std::sin(a) * t2));
      const double h = restingHeight(points, centre, trial);
      if (h < bestTrialHeight) {
        bestTrialHeight = h;
        bestTrial = trial;
      }
    }
    if (bestTrialHeight < best) {
      best = bestTrialHeight;
      up = bestTrial;
    } else {
      step *= 0.5;
    }
  }
  return up;
}

glm::dmat3 uprightRotation(const DVec3& up, const DVec3& forward) {
  const DVec3 y = glm::normalize(up);
  DVec3 x = forward - glm::dot(forward, y) * y;
  if (!(glm::length(x) > 1e-9)) x = tangents(y)[0];
  x = glm::normalize(x);
  const DVec3 z = glm::cross(x, y);
  // Rows x, y, z: R·v = (x·v, y·v, z·v). glm is column-major, so build the transpose.
  return glm::transpose(glm::dmat3(x, y, z));
}

}  // namespace sprig::organisms
