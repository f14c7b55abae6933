#include "render/camera.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sprig::render {

CameraBasis Camera::basis() const {
  CameraBasis b;
  b.forward = glm::normalize(target - position);
  Vec3 u = up;
  if (glm::length(glm::cross(b.forward, u)) < 1e-6f) u = std::abs(b.forward.y) < 0.9f ? Vec3(0, 1, 0) : Vec3(0, 0, 1);
  b.right = glm::normalize(glm::cross(b.forward, u));
  b.up = glm::cross(b.right, b.forward);
  return b;
}

float Camera::pixelPerDepth(int height) const {
  return 2.0f * std::tan(0.5f * static_cast<float>(radians(fovYDeg))) / static_cast<float>(height);
}

PixelScale Camera::pixelScale(int height) const {
  PixelScale s;
  s.eye = position;
  s.forward = basis().forward;
  s.pixelPerDepth = pixelPerDepth(height);
  return s;
}

float PixelScale::nearestPixel(const Box3& box) const {
  if (box.empty()) return 0.0f;
  // The depth along forward is linear, so its minimum over the box is at a corner.
  float depth = std::numeric_limits<float>::infinity();
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner((c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y, (c & 4) ? box.hi.z : box.lo.z);
    depth = std::min(depth, glm::dot(corner - eye, forward));
  }
  return depth > 0.0f && std::isfinite(depth) ? pixelPerDepth * depth : 0.0f;
}

float pixelCellSize(float ownCell, const PixelScale& pixels, const Box3& box, float cellPixels) {
  if (!(ownCell > 0.0f)) return ownCell;
  return std::max(ownCell, cellPixels * pixels.nearestPixel(box));
}

FilmRays Camera::filmRays(int width, int height) const {
  FilmRays f;
  f.position = position;
  f.basis = basis();
  f.tanY = std::tan(0.5f * static_cast<float>(radians(fovYDeg)));
  f.tanX = f.tanY * static_cast<float>(width) / static_cast<float>(height);
  f.width = static_cast<float>(width);
  f.height = static_cast<float>(height);
  return f;
}

Ray Camera::generateRay(float px, float py, int width, int height) const { return filmRays(width, height).ray(px, py); }

bool Camera::project(const Vec3& p, int width, int height, Vec2& film) const {
  const CameraBasis b = basis();
  Vec3 d = p - position;
  float z = glm::dot(d, b.forward);
  if (z <= 0) return false;
  float tanY = std::tan(0.5f * static_cast<float>(radians(fovYDeg)));
  float tanX = tanY * static_cast<float>(width) / static_cast<float>(height);
  float sx = glm::dot(d, b.right) / (z * tanX);
  float sy = glm::dot(d, b.up) / (z * tanY);
  film = {(sx + 1.0f) * 0.5f * static_cast<float>(width), (1.0f - sy) * 0.5f * static_cast<float>(height)};
  return true;
}

Vec3 directionFromAngles(double azimuthDeg, double elevationDeg) {
  double az = radians(azimuthDeg), el = radians(elevationDeg);
  return Vec3(static_cast<float>(std::sin(az) * std::cos(el)), static_cast<float>(std::sin(el)),
              static_cast<float>(std::cos(az) * std::cos(el)));
}

Camera orbitCamera(const Vec3& target, double azimuthDeg, double elevationDeg, double distance, double fovYDeg) {
  Camera c;
  c.target = target;
  c.position = target + static_cast<float>(distance) * directionFromAngles(azimuthDeg, elevationDeg);
  c.fovYDeg = static_cast<float>(fovYDeg);
  return c;
}

namespace {

bool inRange(const Vec3& p) {
  for (int a = 0; a < 3; ++a)
    if (!(std::abs(p[a]) <= kMaxRenderCoordinate)) return false;  // (false for NaN)
  return true;
}

}  // namespace

bool boxInRenderRange(const Box3& box) { return box.empty() || (inRange(box.lo) && inRange(box.hi)); }

std::string cameraProblem(const Camera& c) {
  if (!inRange(c.position)) return "the camera's position is not finite or lies beyond 1e15";
  if (!inRange(c.target)) return "the camera's target is not finite or lies beyond 1e15";
  const Vec3 view = c.target - c.position;
  if (!(glm::length(view) > 0)) return "the camera's target is its position (no view direction)";
  if (!(glm::length(c.up) > 0) || !std::isfinite(glm::length(c.up))) return "the camera's up vector is zero or not finite";
  if (!(c.fovYDeg > 0 && c.fovYDeg < 180)) return "the camera's field of view is outside (0, 180) degrees";
  const CameraBasis b = c.basis();
  for (const Vec3& v : {b.right, b.up, b.forward})
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return "the camera's frame is not finite";
  return {};
}

Camera frameBounds(const Box3& boxIn, const ViewSpec& view, double aspect) {
  if (!boxInRenderRange(boxIn)) throw std::invalid_argument("frameBounds: the box is not finite or lies beyond 1e15");
  Box3 box = boxIn.empty() ? Box3{Vec3(-0.5f), Vec3(0.5f)} : boxIn;
  {
    // Step 0: a box smaller than float resolution at its place grows to the least size.
    const Vec3 reach = glm::max(glm::abs(box.lo), glm::abs(box.hi));
    const float least = std::max(1e-15f, 1e-5f * std::max(reach.x, std::max(reach.y, reach.z)));
    const Vec3 size = box.size();
    if (std::max(size.x, std::max(size.y, size.z)) < least) {
      const Vec3 c = box.center();
      box = Box3{c - 0.5f * least, c + 0.5f * least};
    }
  }
  // Work in double precision in the camera frame centered on the box.
  glm::dvec3 center = glm::dvec3(box.center());
  glm::dvec3 toViewer = glm::dvec3(directionFromAngles(view.azimuthDeg, view.elevationDeg));
  glm::dvec3 forward = -toViewer;
  glm::dvec3 upHint = std::abs(forward.y) > 0.999 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
  glm::dvec3 right = glm::normalize(glm::cross(forward, upHint));
  glm::dvec3 up = glm::cross(right, forward);

  double margin = std::clamp(view.margin, 0.0, 0.9);
  double tanY = std::tan(0.5 * radians(view.fovYDeg)) * (1.0 - margin);
  double tanX = std::tan(0.5 * radians(view.fovYDeg)) * aspect * (1.0 - margin);

  std::array<glm::dvec3, 8> local;
  for (int i = 0; i < 8; ++i) {
    glm::dvec3 p((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    glm::dvec3 q = p - center;
    local[i] = {glm::dot(q, right), glm::dot(q, up), glm::dot(q, forward)};
  }
  // For a camera at distance d behind the center, panned by s along an axis, corner i
  // projects inside the frame iff |a_i - s| <= k (z_i + d): an interval in s per corner.
  // Feasible s exists iff max_i(a_i - k(z_i+d)) <= min_i(a_i + k(z_i+d)); that holds for
  // every d above a threshold, found by bisection.
  auto interval = [&](double d, int axis, double k, double& lo, double& hi) {
    lo = -1e300;
    hi = 1e300;
    for (const auto& q : local) {
      double a = axis == 0 ? q.x : q.y;
      double depth = q.z + d;
      lo = std::max(lo, a - k * depth);
      hi = std::min(hi, a + k * depth);
    }
    return lo <= hi;
  };
  auto feasible = [&](double d) {
    double l0, h0, l1, h1;
    for (const auto& q : local)
      if (q.z + d <= 1e-9) return false;
    return interval(d, 0, tanX, l0, h0) && interval(d, 1, tanY, l1, h1);
  };
  double extent = glm::length(glm::dvec3(box.size())) + 1e-9;
  double lo = 0.0, hi = extent;
  while (!feasible(hi)) hi *= 2.0;
  for (int it = 0; it < 100; ++it) {
    double mid = 0.5 * (lo + hi);
    (feasible(mid) ? hi : lo) = mid;
  }
  // Pan so the projected extent is centered: max_i + min_i of (a_i - s)/(z_i + d) = 0,
  // decreasing in s; the centered pan lies inside the feasible interval.
  const double d = hi;
  auto centeredPan = [&](int axis, double k) {
    double l, h;
    interval(d, axis, k, l, h);
    for (int it = 0; it < 100; ++it) {
      double s = 0.5 * (l + h), mx = -1e300, mn = 1e300;
      for (const auto& q : local) {
        double x = ((axis == 0 ? q.x : q.y) - s) / (q.z + d);
        mx = std::max(mx, x);
        mn = std::min(mn, x);
      }
      (mx + mn > 0 ? l : h) = s;
    }
    return 0.5 * (l + h);
  };
  glm::dvec3 eye = center - d * forward + centeredPan(0, tanX) * right + centeredPan(1, tanY) * up;

  Camera c;
  c.position = Vec3(eye);
  c.target = Vec3(eye + d * forward);
  c.up = Vec3(up);
  c.fovYDeg = static_cast<float>(view.fovYDeg);
  return c;
}

}  // namespace sprig::render
