/// The tables of backends/backends.h linked into the program (every program but `sprig`).

#include "backends/backends.h"

namespace sprig {

const detail::ImageBackend& detail::imageBackend() { return backends::oiioImage(); }
const textures::detail::TextureBackend& textures::detail::textureBackend() { return backends::oiioTexture(); }
const organisms::detail::VolumeBackend& organisms::detail::volumeBackend() { return backends::vdbVolume(); }
const solids::detail::MeshDistanceBackend& solids::detail::meshDistanceBackend() { return backends::vdbMeshDistance(); }

}  // namespace sprig
