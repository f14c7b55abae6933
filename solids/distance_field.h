#pragma once
/// Signed distance fields of layered solids (Cutler et al. §2.4, §4.2): negative inside,
/// positive outside, in world units.
///
/// A field is a small tree: closed triangle meshes (their signed distance on a grid from
/// OpenVDB's meshToSignedDistanceField, then trilinear samples), analytic primitives
/// (sphere, box, cylinder, ground plane), and combinations (union = min, intersection =
/// max, subtraction = max(a, -b), and a similarity transform that carries the paper's
/// scaling). A field is only ever sampled at a batch of points; a mesh's grid is built for
/// the batch's box at the requested cell and band, so far from the surface values are
/// clamped to ±band (the sign stays right: OpenVDB flood-fills the inside of a closed
/// mesh). Callers ask for a band wider than every layer boundary they compare with.

#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "core/polymesh.h"
#include "core/types.h"

namespace sprig::solids {

/// One signed distance field. Immutable after construction; sample() is thread-safe.
class DistanceField {
 public:
  virtual ~DistanceField() = default;
  /// Signed distances at points. cellWorld is the sampling grid's edge (mesh fields build
  /// their grid at it); values with |d| > bandWorld may be clamped to ±bandWorld.
  /// Cost: analytic O(n); a mesh O(n + triangles·band³/cell³) (OpenVDB, multi-threaded).
  virtual std::vector<float> sample(const std::vector<Vec3>& points, double cellWorld, double bandWorld) const = 0;
  /// Box holding the field's interior (d <= 0), or nullopt when unbounded (a ground plane).
  virtual std::optional<DBox3> bounds() const = 0;
  /// World units per unit of value, at most: 1 for a distance, the largest speed for a
  /// front's arrival time (solids/front_field.h). A layer boundary b lies within
  /// b·reach() of the zero set (the default grid's margin).
  virtual double reach() const { return 1.0; }
};

using FieldPtr = std::shared_ptr<const DistanceField>;

/// A closed, consistently oriented triangle mesh as a field (counter-clockwise faces seen from outside).
/// Throws std::invalid_argument when the mesh has no faces.
FieldPtr meshField(const PolyMesh& mesh);
/// Sphere of radius r about center.
FieldPtr sphereField(const DVec3& center, double radius);
/// Axis-aligned box (exact Euclidean distance, also at edges and corners).
FieldPtr boxField(const DVec3& center, const DVec3& size);
/// Capped cylinder of radius and height about center, its axis along unit axis.
FieldPtr cylinderField(const DVec3& center, double radius, double height, const DVec3& axis);
/// Half-space below the plane n·p = height (n unit): d = n·p - height. Unbounded.
FieldPtr groundPlaneField(const DVec3& normal, double height);
/// Union (min) of fields. At least one.
FieldPtr unionField(std::vector<FieldPtr> fields);
/// Intersection (max) of fields. At least one.
FieldPtr intersectionField(std::vector<FieldPtr> fields);
/// a minus b: max(a, -b).
FieldPtr subtractionField(FieldPtr a, FieldPtr b);
/// child scaled by s > 0, turned by angleDeg about unit axis, then moved by translate:
/// d(p) = s · child(R⁻¹(p - t) / s), still a Euclidean distance.
FieldPtr transformField(FieldPtr child, double scale, const DVec3& axis, double angleDeg, const DVec3& translate);
/// child grown by `by` >= 0 world units: d(p) = child(p) - by. Where child is a Euclidean
/// distance, its solid {d <= 0} is the child's dilated by a ball of radius `by` (and d is
/// the exact distance outside it), so walls thicken by 2·by and holes narrower than 2·by
/// close. Bounds grow by `by`. Throws std::invalid_argument when `by` < 0.
FieldPtr offsetField(FieldPtr child, double by);

/// The first edge of mesh used by only one face, as "between vertices A and B (1-based)
/// of the face at LOC"; nullopt when the mesh is closed. faceLocs say where.
struct OpenEdge {
  uint32_t a = 0, b = 0;  ///< 0-based vertex indices
  size_t face = 0;        ///< the face that has it
};
std::optional<OpenEdge> firstOpenEdge(const PolyMesh& mesh);

}  // namespace sprig::solids
