#pragma once
/// Writers of tetrahedral meshes with materials, each written atomically (core/atomic_file.h):
///
/// - Gmsh MSH 4.1 ASCII: $MeshFormat, $PhysicalNames (one 3-D physical group per material
///   used), $Entities (one volume entity per material carrying its physical tag: without
///   it readers lose the groups), $Nodes (one block), $Elements (type 4, one block per
///   material). Node and element tags are 1-based.
/// - VTK XML unstructured grid (.vtu, ascii): points, tetrahedra (cell type 10), a cell
///   array `material` (material id) for ParaView.
/// - Medit .mesh (MeshVersionFormatted 2): vertices, tetrahedra with the material id + 1 as reference.
///
/// Numbers are printed with %.9g (float-exact positions); the bytes depend only on the mesh.

#include <filesystem>
#include <string>
#include <vector>

#include "solids/material.h"
#include "solids/solid.h"

namespace sprig::solids {

/// Tetrahedral mesh formats by extension.
enum class TetFormat { Msh, Vtu, Medit };

/// The format of path's extension (.msh, .vtu, .mesh; case-insensitive), or nullopt.
std::optional<TetFormat> tetFormatFor(const std::filesystem::path& path);

/// The file's bytes. materials name the ids (for physical names).
std::string formatTetMesh(const TetMesh& mesh, const std::vector<Material>& materials, TetFormat format);

/// Writes mesh to path atomically in the format of its extension. Throws
/// std::invalid_argument for another extension, std::runtime_error when it cannot write.
void writeTetMesh(const TetMesh& mesh, const std::vector<Material>& materials, const std::filesystem::path& path);

}  // namespace sprig::solids
