#pragma once
/// The iso-surface of a scalar volume (a CT scan) as a closed quad mesh, through OpenVDB's
/// volumeToMesh (uniform, adaptivity 0: dual quads, one vertex per crossed cell), reached
/// through organisms/detail/volume_backend.h.

#include "core/inr_volume.h"
#include "core/polymesh.h"

namespace sprig::organisms {

/// The surface where the volume equals iso, the region above iso inside (CT convention:
/// bone is dense). The volume is padded with one layer of "outside" voxels, so a region
/// touching the volume's border is closed there. Quads are counter-clockwise seen from
/// outside. Throws std::invalid_argument when no voxel lies above iso or every voxel does.
PolyMesh isoSurface(const ScalarVolume& volume, double iso);

}  // namespace sprig::organisms
