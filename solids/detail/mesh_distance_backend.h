#pragma once
/// OpenVDB's narrow-band signed distance of a closed triangle mesh, as a table of one
/// function: solids/distance_field.cpp's one dependency on OpenVDB. Like core's image
/// backend (core/detail/image_backend.h, whose file comment says why), the table is
/// implemented in backends/ and reached through meshDistanceBackend(), which the program
/// provides.

#include <memory>
#include <vector>

#include "core/types.h"

namespace sprig::solids::detail {

/// A signed distance grid. Immutable; sample() is thread-safe.
class DistanceGrid {
 public:
  virtual ~DistanceGrid() = default;
  /// Trilinear samples at points[0..count) into out[0..count).
  virtual void sample(const Vec3* points, size_t count, float* out) const = 0;
};

/// The mesh distance operations.
struct MeshDistanceBackend {
  /// The narrow-band signed distance grid (negative inside; the inside flood-filled, so
  /// the mesh must be closed) of triangles over points, voxel edge cell, voxel centres on
  /// the lattice through origin, bandVoxels voxels each side: OpenVDB's
  /// meshToSignedDistanceField.
  std::unique_ptr<DistanceGrid> (*build)(const std::vector<Vec3>& points, const std::vector<glm::uvec3>& triangles,
                                         double cell, const Vec3& origin, float bandVoxels);
};

/// The mesh distance operations of this program. Throws std::runtime_error when the
/// `sprig` binary cannot load libsprig_backends.so.
const MeshDistanceBackend& meshDistanceBackend();

}  // namespace sprig::solids::detail
