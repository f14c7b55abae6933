#pragma once
/// The tetrahedral cells of a grid's cubes, on a coarsened octree (Cutler et al. 2002, §4.3
/// and §4.4, Fig. 4).
///
/// Each cubic cell splits into five tetrahedra, alternating the orientation of the central
/// one so that face diagonals match between neighbours (§4.3). With coarsening, 2×2×2
/// blocks of cells whose nodes all lie in one region of every volume (no interface crosses
/// them) merge into one cube of the next level, bottom-up, while every leaf touching the
/// block (across a face, an edge or a corner) is at most one level finer: the paper's
/// restriction that bounds the solid angles of the transition tetrahedra.
///
/// A leaf whose faces all meet leaves of its own size with no extra vertices splits into
/// five tetrahedra like a cell of its level. Any other leaf (a transition cell) is a fan
/// from its centre over its triangulated faces: a face whose neighbour is finer splits into
/// its four quarters; a square with vertices of finer leaves on its edges is a fan from its
/// centre; a plain square takes the diagonal the five-tetrahedra pattern of its level gives
/// it (the two corners whose level coordinates sum to an odd number). Both sides of every
/// square compute the same triangles, so faces match and no T-junction remains. Every vertex
/// is a grid node (the centres of cubes of two or more cells are nodes).

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "solids/solid.h"

namespace sprig::solids {

/// A node's class for coarsening: nodes of one class lie in the same region of every
/// volume; kMixedClass never merges (a node on a boundary or in a procedural layer).
constexpr uint64_t kMixedClass = ~uint64_t(0);

/// Counts of cellTetrahedra.
struct CellStats {
  size_t leaves = 0;        ///< kept leaves (cubes of any level)
  size_t coarseLeaves = 0;  ///< kept leaves of level >= 1
  size_t transition = 0;    ///< kept leaves meshed as a fan from their centre
};

/// Whether the block of size × size × size cells at cell `base` may merge although its
/// nodes' classes differ (the fields are "accurately represented by interpolation" there).
using MergeTest = std::function<bool(const std::array<int, 3>& base, int size)>;

/// The tetrahedra (positively oriented, node ids) of the cubes of grid kept by keep(8 corner
/// node ids, corner c = dx + 2·dy + 4·dz), merged up to `levels` octree levels where
/// nodeClass (per node) allows, or where interpolated (when given) accepts a block whose
/// children are leaves of one level; levels = 0 gives the uniform five tetrahedra per cell.
/// Deterministic at any thread count (interpolated is called concurrently); in the order
/// of the leaves' first cells.
std::vector<std::array<uint32_t, 4>> cellTetrahedra(const Grid& grid, int levels, const std::vector<uint64_t>& nodeClass,
                                                    const std::function<bool(const uint32_t*)>& keep,
                                                    CellStats* stats = nullptr, const MergeTest& interpolated = {});

}  // namespace sprig::solids
