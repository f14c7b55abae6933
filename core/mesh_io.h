#pragma once
/// Mesh export: binary PLY, Wavefront OBJ (+MTL) and glTF 2.0 binary (.glb).
///
/// Every writer builds the whole file in memory, writes it to a temporary next to the
/// destination (core/atomic_file.h) and renames it into place, so a reader never sees a
/// half-written mesh and a failed write leaves nothing behind. Output bytes depend only on
/// the mesh and the options (floats are printed in their shortest round-trip form), so the
/// same mesh gives the same file.
///
/// Optional per-vertex arrays (normals, uvs, colors) are written when they have one entry
/// per vertex; colors are linear RGB in the Mesh and are written sRGB-encoded as 8-bit in
/// PLY, as linear floats in glTF (COLOR_0, as the specification asks) and as sRGB floats
/// after the position in OBJ (the common `v x y z r g b` extension).

#include <filesystem>
#include <string>

#include "core/mesh.h"
#include "core/types.h"

namespace sprig {

/// Mesh file formats Sprig writes.
enum class MeshFormat { Ply, Obj, Glb };

/// Options shared by the mesh writers.
struct MeshWriteOptions {
  /// Name of the material in OBJ/MTL and glTF (OBJ uses `<name>_<id>` when the mesh has
  /// per-triangle material ids).
  std::string materialName = "sprig";
  /// Diffuse/base colour of the material, linear RGB in [0,1].
  Vec3 baseColor{0.8f, 0.8f, 0.8f};
  /// glTF roughness factor in [0,1].
  float roughness = 0.6f;
};

/// The format for a path's extension (.ply, .obj, .glb; case-insensitive).
/// Throws std::invalid_argument naming the path for any other extension.
MeshFormat meshFormatFor(const std::filesystem::path& path);

/// Writes mesh to path in the format its extension names (see meshFormatFor), atomically.
/// Throws std::invalid_argument for an unknown extension or an invalid mesh (an index out
/// of range, an optional array of the wrong length) and std::runtime_error when the file
/// cannot be written (the destination is then left untouched).
void writeMesh(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

/// Binary little-endian PLY: x y z [nx ny nz] [s t] [red green blue] per vertex,
/// `vertex_indices` (uchar count, uint indices) per face, and `material` (uint) per face
/// when the mesh has material ids. Throws as writeMesh.
void writePly(const Mesh& mesh, const std::filesystem::path& path);

/// OBJ with `mtllib`, plus the MTL file beside it (same stem, `.mtl`); both are written
/// atomically, the MTL first. Indices are 1-based; faces are `v/vt/vn` as available.
/// Throws as writeMesh.
void writeObj(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

/// glTF 2.0 binary through TinyGLTF: one mesh, one primitive (triangles), POSITION
/// (with min/max), NORMAL, TEXCOORD_0 (v flipped to glTF's top-left origin), COLOR_0,
/// uint32 indices, one metallic-roughness material. Throws as writeMesh.
void writeGlb(const Mesh& mesh, const std::filesystem::path& path, const MeshWriteOptions& options = {});

}  // namespace sprig
