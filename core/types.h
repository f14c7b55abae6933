#pragma once
/// Common math aliases and the axis-aligned box used across Sprig.
///
/// Geometry that is evaluated in bulk (fields, meshes, rays) is single precision;
/// the turtle and anything that accumulates many transforms uses double precision.

#include <glm/glm.hpp>

#include <algorithm>
#include <cstdint>
#include <limits>

namespace sprig {

/// GLM vectors and matrices under Sprig's names (D for double precision).
using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using Vec4 = glm::vec4;
using Mat3 = glm::mat3;
using Mat4 = glm::mat4;
using DVec3 = glm::dvec3;
using DMat3 = glm::dmat3;

/// Axis-aligned box; empty when lo > hi on any axis (the default).
template <class V>
struct BasicBox {
  V lo{std::numeric_limits<typename V::value_type>::max()};
  V hi{std::numeric_limits<typename V::value_type>::lowest()};

  /// True when the box holds no point.
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  /// Grows the box to hold p.
  void extend(const V& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  /// Grows the box to hold b.
  void extend(const BasicBox& b) {
    if (!b.empty()) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
  }
  /// Grows the box by r on every side.
  BasicBox expanded(typename V::value_type r) const { return empty() ? *this : BasicBox{lo - r, hi + r}; }
  /// Midpoint of lo and hi.
  V center() const { return (lo + hi) * typename V::value_type(0.5); }
  /// hi - lo; zero for an empty box.
  V size() const { return empty() ? V(0) : hi - lo; }
  /// True when p lies inside or on the boundary.
  bool contains(const V& p) const {
    return p.x >= lo.x && p.y >= lo.y && p.z >= lo.z && p.x <= hi.x && p.y <= hi.y && p.z <= hi.z;
  }
  /// True when the boxes share at least a boundary point.
  bool overlaps(const BasicBox& b) const {
    return !(b.lo.x > hi.x || b.hi.x < lo.x || b.lo.y > hi.y || b.hi.y < lo.y || b.lo.z > hi.z || b.hi.z < lo.z);
  }
  /// The common part of the boxes (empty() when they do not overlap).
  BasicBox intersected(const BasicBox& b) const { return {glm::max(lo, b.lo), glm::min(hi, b.hi)}; }
};

/// Float and double axis-aligned boxes.
using Box3 = BasicBox<Vec3>;
using DBox3 = BasicBox<DVec3>;

/// pi in double precision.
constexpr double kPi = 3.14159265358979323846;

/// Degrees to radians.
constexpr double radians(double deg) { return deg * (kPi / 180.0); }

}  // namespace sprig
