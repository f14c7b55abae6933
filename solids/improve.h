#pragma once
/// Quality improvement of a tetrahedral mesh by flips, half-edge collapses and smoothing
/// (Cutler et al. 2002, §4.4; after Freitag and Ollivier-Gooch 1997).
///
/// The paper's loop: for q = 1 … 10, every tetrahedron of quality at most q is offered the
/// actions in turn (2→3, 3→2 and 2→2 flips, half-edge collapses, moving a vertex toward the
/// centroid of its neighbours), and an action is taken only when the smallest quality of
/// the tetrahedra it touches rises and no interface moves further than the tolerance.
///
/// Interfaces (the visible interface and the faces between two materials) are kept:
/// - 2→3 and 3→2 flips only replace faces and edges inside one material, so every interface
///   face stays; a 2→2 flip swaps the diagonal of two visible faces that lie in one plane
///   (within the tolerance), so the visible interface keeps its shape (the 4→4 flip that
///   would do the same on a face between two materials is not built);
/// - a vertex inside one material collapses into any neighbour;
/// - a vertex on one interface sheet collapses only along an edge of that sheet, a vertex on a
///   curve where interfaces meet only along that curve, a vertex where curves meet never;
///   the interface may then move by at most `interfaceTolerance` (measured as the distance
///   from the removed vertex to the interface triangles that replace its own);
/// - smoothing moves only vertices on no interface.
/// Every result has positive tetrahedra whose faces match (the link condition of Dey et al.
/// 1999 is checked before each collapse). Sequential: the same bytes at any thread count.

#include <cstddef>

#include "solids/solid.h"

namespace sprig::solids {

/// Options of improveQuality.
struct ImproveOptions {
  /// The last quality threshold of the paper's loop (q = 1, 2, …, up to this; 0..10).
  double qualityBelow = 10;
  /// World units an interface may move at a collapse (0: only where it is flat).
  double interfaceTolerance = 0;
  bool flips = true;      ///< 2→3, 3→2 and 2→2 flips
  bool collapses = true;  ///< half-edge collapses
  bool smoothing = true;  ///< moving free vertices toward their neighbours' centroid
  /// Ideal volume = total volume / targetCount (0 = the mesh's count before improvement).
  size_t targetCount = 0;
};

/// Counts and quality of one improveQuality.
struct ImproveStats {
  QualityStats before, after;  ///< against the same ideal volume
  size_t tetsBefore = 0, tetsAfter = 0;
  size_t flips23 = 0, flips32 = 0, flips22 = 0, collapses = 0, moves = 0;
};

/// Improves the tetrahedra of mesh in place (see the header comment), removing unused
/// vertices at the end (the others keep their order). Cost: about O(tets · passes) local
/// operations on a mesh whose vertices have bounded degree.
ImproveStats improveQuality(TetMesh& mesh, const ImproveOptions& options = {});

}  // namespace sprig::solids
