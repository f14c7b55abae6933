#pragma once
/// Levels of detail of an exported model (`sprig mesh`, docs/MESHES.md "Levels of detail").
///
/// A chain of levels of the same named parts: LOD0 within a triangle budget, each further
/// level about kLodRatio of the one before, down to the far level. Surfaces are reduced by
/// meshoptimizer's edge collapses (organisms::simplifyToCount: vertices are only removed,
/// so every vertex that remains keeps its normal, uvs and colour; borders between parts are
/// locked); parts of many small pieces (leaves: ExportPart::scattered) keep an evenly spread
/// share of their pieces, each grown about its centroid so that their total area stays.
/// Textures over the surface's own (u, v) (bark, a shell's whorl, cpfg images) stay as they
/// are; an atlas (one patch per triangle) is baked again for each level, and so is one for a
/// part whose colours vary but had too many triangles for an atlas (its colours were clamped
/// in COLOR_0): from the full part's surface (model/detail_maps.h: its colours and a
/// tangent-space normal map of the relief the level lost), or, where that cannot be done
/// (leaves, a part without normals), from the vertex colours that remain (atlasVertexColors).

#include <cstddef>
#include <filesystem>
#include <vector>

#include "core/mesh_io.h"
#include "core/types.h"

namespace sprig {

/// Each level has about this fraction of the triangles of the level before.
inline constexpr double kLodRatio = 0.25;
/// At most this many levels (LOD0 to LOD3).
inline constexpr int kLodMaxLevels = 4;
/// No level is made below about this many triangles (the chain stops earlier; 2 % below
/// it passes, as a level may end a few triangles under its target).
inline constexpr size_t kLodMinTriangles = 500;
/// A level is kept only when it has at most this fraction of the triangles of the level
/// before (simplification that cannot get further, e.g. at locked borders, ends the chain).
inline constexpr double kLodMaxKeep = 0.75;
/// The smallest budget `--lod N` accepts.
inline constexpr size_t kLodMinBudget = 1000;
/// `sprig mesh` with levels and no --cell polygonizes a tree's wood at the cell that gives
/// about this many times LOD0's budget (lodCellSize, model/mesh_parts.h), never finer than
/// the automatic cell: LOD0 is simplified from it with this margin.
inline constexpr size_t kLodCellMargin = 8;

/// The detail maps' rays reach this many times a level's simplification error (meshoptimizer's
/// estimate, summed over the chain from the full mesh) ...
inline constexpr float kDetailReach = 2.0f;
/// ... and at least this fraction of the part's extent (the largest side of its box).
inline constexpr float kDetailReachFloor = 1e-3f;

/// What buildLodChain's detail maps did.
struct LodMapReport {
  size_t maps = 0;    ///< parts' levels that got a normal map (and a colour atlas of the full mesh, unless the part keeps an image over its own uvs)
  size_t texels = 0;  ///< texels baked
  size_t hits = 0;    ///< of them, with a hit of the full mesh
  double seconds = 0; ///< wall-clock time of the baking (scenes of the full parts included)
};

/// The MSFT_screencoverage of level i (LodLevel::screenCoverage) is kLodRatio^(i+1): the
/// next level has as many triangles per pixel there as LOD0 at a full screen; the far
/// level's is 0 (never culled).

/// The level-of-detail chain of a model's parts: LOD0 is parts unchanged when their
/// triangles are within budget, else every part reduced to its share of budget (scattered
/// parts keep all their triangles up to half the budget between them; the surfaces share
/// the rest in proportion to their triangles; when locked borders keep LOD0 above the
/// budget, the shares shrink by the overshoot, at most twice); then further levels of kLodRatio of the level
/// before, at most kLodMaxLevels, while a level would have at least kLodMinTriangles and
/// does get below kLodMaxKeep of the level before. Triangle counts strictly decrease.
/// Parts without triangles stay empty. Every level is moved by the offset that stands LOD0
/// on the ground (groundOffset: simplification may remove the lowest or outermost vertices);
/// moved, when given, receives it. The last of two or more such levels has its scattered
/// parts (leaves) as alpha-tested cards of the full parts' leaves, one a leaf
/// (model/leaf_cards.h leafCards: half as many cards as that level kept leaf triangles).
/// When it has leaves, one more level follows, beyond kLodMaxLevels and kLodMinTriangles:
/// the crown level, the far impostor, its surfaces kLodRatio of the level before and its
/// leaves crown cards, several leaves a card (leaf_cards.h crownCards: all the full part's
/// leaves in ⌊kLodRatio · (the level before's leaf triangles) / (2 · kCrownCardsPerCluster)⌋
/// clusters, at least one), made only if the level has fewer triangles than the one before.
/// Deterministic. Cost: one simplification of the full parts
/// (O(T log T)), then of each level (a quarter each).
///
/// Every simplified surface part (not scattered; with normals; its level's texture an atlas
/// or none) of every level, LOD0 included when it was reduced, then gets maps baked from
/// its full mesh (model/detail_maps.h bakeDetailMaps): a tangent-space normal map
/// (PartMaterial::normalTexture) and an atlas of the full mesh's colours at the same points,
/// instead of the level's own vertex colours. The rays reach kDetailReach times the
/// simplification error summed along the chain, at least kDetailReachFloor of the part's
/// extent. maps, when given, receives what was baked.
std::vector<LodLevel> buildLodChain(const std::vector<ExportPart>& parts, size_t budget, Vec3* moved = nullptr,
                                    LodMapReport* maps = nullptr);

/// The levels `sprig mesh` writes: buildLodChain(parts, budget), or parts alone as one
/// level when budget is 0 (--lod none); moved as buildLodChain's (zero without levels).
std::vector<LodLevel> lodLevels(std::vector<ExportPart> parts, size_t budget, Vec3* moved = nullptr,
                                LodMapReport* maps = nullptr);

/// Writes levels to path as `sprig mesh` does: each further level's own file
/// (lodPath(path, K): STEM_lodK.EXT for K >= 1, the parts as writeParts writes them; a .glb
/// also STEM_lod0.glb) first, then path itself (.glb: every level, writePartLevels with
/// MSFT_lod; .obj and .ply: LOD0). One level: path alone, as writeParts. Each file is written atomically, and a failure removes the files of this call
/// already written. Every texture image is encoded to PNG once for all the files
/// (PngReuse). Returns LOD0's reports. Throws as writeParts.
std::vector<PartWriteReport> writeLevels(const std::vector<LodLevel>& levels, const std::filesystem::path& path);

/// Total triangles of parts.
size_t partTriangles(const std::vector<ExportPart>& parts);

}  // namespace sprig
