#pragma once
/// Edge-collapse simplification that keeps a manifold triangle mesh manifold.
///
/// Garland and Heckbert's quadric error ("Surface simplification using quadric error
/// metrics", 1997) orders the collapses; each collapse moves one endpoint onto the other
/// (no new positions, so the vertices stay on the input surface). A collapse is made only
/// when it is a legal move: the edge has two faces, the endpoints share exactly the two
/// neighbours opposite the edge (the link condition of Dey, Edelsbrunner, Guha and
/// Nekhayev, "Topology preserving edge contraction", 1999), no face flips or becomes
/// degenerate, and no vertex is left with fewer than three neighbours. Vertices on the
/// boundary (or on an edge of more than two faces) never move and are never removed.
///
/// organisms/simplify.h uses this where meshoptimizer's simplifier, which does not test
/// the link condition, pinches the surface.

#include <cstdint>
#include <vector>

#include "core/types.h"

namespace sprig::organisms {

/// The triangles left by collapseEdges and the error of the costliest collapse.
struct EdgeCollapseResult {
  std::vector<uint32_t> indices;  ///< three per triangle, into the input positions
  /// The costliest collapse's error: the square root of the area-weighted mean squared
  /// distance of the kept vertex to the planes of the faces merged into it, in position units.
  float error = 0;
};

/// Collapses edges of the triangles `indices` (three per face, into positions; vertices
/// welded, faces without repeated vertices), cheapest first, until at most targetFaces
/// faces are left, no legal collapse is left, or the next one costs more than maxError
/// (an error as EdgeCollapseResult::error, in position units). Deterministic. The faces keep
/// their input order. Cost: O(T log T) for T triangles.
EdgeCollapseResult collapseEdges(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices,
                                 size_t targetFaces, float maxError);

}  // namespace sprig::organisms
