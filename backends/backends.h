#pragma once
/// Sprig's adapters of the libraries that are expensive to load: OpenImageIO (image files,
/// texture lookups) and OpenVDB (mesh distance fields, iso-surfaces).
///
/// Linking OpenImageIO makes the dynamic loader map and relocate some 250 shared libraries
/// (about 150 k relocations) and OpenVDB another 60 k relocations before main runs: about
/// 0.2 s for every process, even `sprig --version`. So each module that needs one of these
/// libraries declares the few operations it uses as a table of functions in its detail/
/// folder (core/detail/image_backend.h, textures/detail/texture_backend.h,
/// organisms/detail/volume_backend.h, solids/detail/mesh_distance_backend.h), and only the
/// files of this folder include the libraries. Who provides the tables is the program's
/// choice, made when it is linked:
/// - `sprig_backends_static` (backends/linked.cpp): the tables are linked in; every test,
///   bench and fuzz target uses it;
/// - `sprig_backends_loader` (backends/loader.cpp): the `sprig` binary opens
///   libsprig_backends.so (these files and backends/plugin.cpp), found beside the binary,
///   on the first call of any table, so `check`, `derive` and `--version` never load them.
/// The tables pass standard types and Sprig's plain structs only; libsprig_backends.so is
/// linked with -z defs, so it cannot come to depend on code that lives in the binary.

#include "core/detail/image_backend.h"
#include "organisms/detail/volume_backend.h"
#include "solids/detail/mesh_distance_backend.h"
#include "textures/detail/texture_backend.h"

namespace sprig::backends {

/// core's image files through OpenImageIO (backends/oiio_image.cpp).
const detail::ImageBackend& oiioImage();
/// textures' filtered lookups through OpenImageIO's TextureSystem (backends/oiio_texture.cpp).
const textures::detail::TextureBackend& oiioTexture();
/// organisms' iso-surfaces through OpenVDB (backends/vdb_volume.cpp).
const organisms::detail::VolumeBackend& vdbVolume();
/// solids' mesh distance fields through OpenVDB (backends/vdb_mesh_distance.cpp).
const solids::detail::MeshDistanceBackend& vdbMeshDistance();

/// Every table, as libsprig_backends.so hands them to the loader.
struct Backends {
  int version;  ///< kBackendsVersion of the build that made the library
  const detail::ImageBackend* image;
  const textures::detail::TextureBackend* texture;
  const organisms::detail::VolumeBackend* volume;
  const solids::detail::MeshDistanceBackend* meshDistance;
};

/// Changes whenever a table's layout does; the loader refuses a library of another version.
inline constexpr int kBackendsVersion = 4;

/// The name of libsprig_backends.so's one exported function: `const Backends* ()`.
inline constexpr const char* kBackendsEntry = "sprig_backends";

}  // namespace sprig::backends
