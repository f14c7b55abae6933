#include "blobtree/detail/geometry.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace sprig::blobtree::detail {

Vec3 perpendicular(Vec3 axis, Vec3 preferred) {
  Vec3 p = preferred - glm::dot(preferred, axis) * axis;
  if (glm::dot(p, p) < 1e-12f) {
    Vec3 t = std::abs(axis.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
    p = t - glm::dot(t, axis) * axis;
  }
  return glm::normalize(p);
}

Box3 cylinderBox(Vec3 origin, Vec3 axis, float h0, float h1, float r) {
  Vec3 e{r * std::sqrt(std::max(0.0f, 1.0f - axis.x * axis.x)), r * std::sqrt(std::max(0.0f, 1.0f - axis.y * axis.y)),
         r * std::sqrt(std::max(0.0f, 1.0f - axis.z * axis.z))};
  Vec3 p0 = origin + h0 * axis, p1 = origin + h1 * axis;
  return Box3{glm::min(p0, p1) - e, glm::max(p0, p1) + e};
}

void axialExtent(const Box3& box, Vec3 origin, Vec3 axis, float& h0, float& h1, float& rmax) {
  h0 = 1e30f;
  h1 = -1e30f;
  rmax = 0.0f;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner{(i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z};
    Vec3 d = corner - origin;
    float h = glm::dot(d, axis);
    h0 = std::min(h0, h);
    h1 = std::max(h1, h);
    rmax = std::max(rmax, glm::length(d - h * axis));
  }
}

Box3 transformBox(const Mat4& m, const Box3& box) {
  if (box.empty() || isHuge(box)) return box;
  Box3 r;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner{(i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z};
    r.extend(Vec3(m * Vec4(corner, 1.0f)));
  }
  return r;
}

float spectralNorm(const Mat3& m) {
  Mat3 a = glm::transpose(m) * m;
  Vec3 v = glm::normalize(Vec3(0.577f, 0.601f, 0.553f));
  float lambda = 0.0f;
  for (int i = 0; i < 64; ++i) {
    Vec3 w = a * v;
    float l = glm::length(w);
    if (l <= 0.0f) return 0.0f;
    lambda = l;
    v = w / l;
  }
  // Power iteration converges from below; inflate, and never exceed the Frobenius norm.
  float frob = std::sqrt(glm::dot(m[0], m[0]) + glm::dot(m[1], m[1]) + glm::dot(m[2], m[2]));
  return std::min(frob, std::sqrt(lambda) * 1.01f);
}

}  // namespace sprig::blobtree::detail
