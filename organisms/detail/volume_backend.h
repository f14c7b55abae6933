#pragma once
/// OpenVDB's volumeToMesh as a table of one function: organisms/iso_surface.cpp's one
/// dependency on OpenVDB. Like core's image backend (core/detail/image_backend.h, whose
/// file comment says why), the table is implemented in backends/ and reached through
/// volumeBackend(), which the program provides.

#include "core/inr_volume.h"
#include "core/polymesh.h"

namespace sprig::organisms::detail {

/// The volume operations.
struct VolumeBackend {
  /// The zero set of the level set `iso - volume` (negative inside), voxels placed by the
  /// volume's voxel size and origin, `background` outside the volume: OpenVDB's uniform
  /// volumeToMesh (adaptivity 0). Quads first, then triangles, as OpenVDB orients them.
  PolyMesh (*levelSetMesh)(const ScalarVolume& volume, double iso, float background);
};

/// The volume operations of this program. Throws std::runtime_error when the `sprig`
/// binary cannot load libsprig_backends.so.
const VolumeBackend& volumeBackend();

}  // namespace sprig::organisms::detail
