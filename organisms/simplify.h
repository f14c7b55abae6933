#pragma once
/// Simplification of any Sprig mesh (a polygonized blob, shell or tree, or a read mesh) to
/// a control mesh of about a chosen face count, for subdivision and procedural detail.
///
/// Three steps through meshoptimizer 0.18 (simplify.cpp is Sprig's only caller of it):
///  1. weld: vertices at the same position become one (meshopt_generateVertexRemap on
///     positions alone, -0 and +0 alike), so seams of normals, uvs or colors do not cut
///     the surface; triangles that collapse to a line or a point by welding are dropped;
///  2. simplify: meshopt_simplify's edge collapses with meshopt_SimplifyLockBorder, so the
///     boundary of an open mesh stays where it is and a closed mesh stays closed; where
///     its result is pinched, organisms/edge_collapse.h's link-checked collapses instead;
///  3. compact: unused vertices are removed, the rest renumbered in order of first use.
/// The result is deterministic: the same mesh gives the same bytes.

#include <cstddef>

#include "core/mesh.h"
#include "core/polymesh.h"

namespace sprig::organisms {

/// What a simplification achieved.
struct SimplifyReport {
  size_t inputTriangles = 0;
  size_t weldedVertices = 0;  ///< vertices after welding coincident positions
  size_t faces = 0;           ///< triangles of the result
  size_t vertices = 0;        ///< vertices of the result
  /// meshoptimizer's error of the result, relative to the mesh's extent (the largest side
  /// of its bounding box); absoluteError is the same in the mesh's units.
  float relativeError = 0;
  float absoluteError = 0;
  /// meshoptimizer's result pinched the surface and Sprig's link-checked collapses
  /// (organisms/edge_collapse.h) made this one instead (see simplifyMesh).
  bool linkChecked = false;
  /// Pairs of a triangle and its reverse (a flap folded back onto its neighbour) removed
  /// from meshoptimizer's result (dropFoldedPairs).
  size_t foldedPairs = 0;
};

/// A simplified mesh and its report.
struct SimplifiedMesh {
  PolyMesh mesh;  ///< triangles as faces; colors kept when the input has them; no faceLocs
  SimplifyReport report;
  /// For each vertex of mesh, the input vertex it is (the lowest-numbered input vertex at
  /// its position): edge collapses move no vertex, so every per-vertex value of the input
  /// (a field normal, texture coordinates) stays valid at the vertex it came from.
  std::vector<uint32_t> source;
};

/// Reduces mesh to about targetFaces triangles (fewer is never asked of meshoptimizer;
/// it may stop above the target when topology or maxRelativeError, relative to the mesh
/// extent, forbids more collapses). Normals, uvs and materials are dropped; colors are
/// kept (at welded vertices, one of the coincident colors).
///
/// When the welded input is manifold, so is the result, and it has the same boundary
/// edges (none for a closed input). meshoptimizer 0.18 alone does not promise that: its
/// edge collapses do not test the link condition and now and then pinch the surface (an
/// edge of four faces) or fold a triangle onto its reverse (for mannequin-devil.off at 43
/// of 65 targets from 50 to 25,000 faces; 103 pinched edges reducing a 1.3 M-triangle
/// sphere to 50,000).
/// Such a result is replaced by Sprig's link-checked collapses (organisms/edge_collapse.h;
/// report.linkChecked says so).
/// Throws std::invalid_argument for an index out of range or a position that is not
/// finite. Cost: O(T log T) for T triangles: 1.3 M triangles to 500 in 1.2-2.3 s on one
/// core of a shared machine, 2.5-3.5 s more when the link-checked collapses run.
/// linkCheck false keeps meshoptimizer's result as it is (faster on millions of triangles;
/// a pinched edge now and then): for levels of detail, which are drawn, not refined. Its
/// folded pairs are removed either way (dropFoldedPairs).
/// lockBorder false lets collapses run along open borders too (they move an open outline
/// inward: leaves of a level of detail), and implies linkCheck false.
SimplifiedMesh simplifyMesh(const Mesh& mesh, size_t targetFaces, float maxRelativeError = 1e-1f, bool linkCheck = true,
                            bool lockBorder = true);

/// Removes, from an index buffer of triangles, every pair of a triangle and its reverse
/// (the same three vertices, opposite orientations): meshoptimizer's folds. Each edge of
/// such a pair has the pair's two faces besides the surface's own, so the rest stays
/// closed and consistently oriented. Triangles on the same three vertices with the same
/// orientation are kept. Keeps the order of the others; returns the number of pairs.
/// O(T log T).
size_t dropFoldedPairs(std::vector<unsigned int>& indices);

/// simplifyMesh(...).mesh.
PolyMesh simplifyToFaceCount(const Mesh& mesh, size_t targetFaces, float maxRelativeError = 1e-1f);

/// Collapses edges of mesh while meshoptimizer's error stays within maxRelativeError of
/// the mesh's extent (simplifyMesh with no face target), and keeps the input's per-vertex
/// arrays (normals, uvs, colours) at the vertices that remain (SimplifiedMesh::source);
/// per-triangle materials are dropped. A closed manifold input stays closed and manifold.
/// report, when given, receives simplifyMesh's report, and source the input vertex of each
/// vertex of the result (for per-vertex data kept outside the mesh). Throws as simplifyMesh.
Mesh simplifyToError(const Mesh& mesh, float maxRelativeError, SimplifyReport* report = nullptr,
                     std::vector<uint32_t>* source = nullptr);

/// Reduces mesh to about targetFaces triangles whatever the error (meshoptimizer's edge
/// collapses, the border locked, without the link-checked replacement: linkCheck false of
/// simplifyMesh) and keeps the input's per-vertex arrays at the vertices that remain, as
/// simplifyToError: a level of detail. lockBorder false: open borders are simplified too
/// (simplifyMesh). report as simplifyToError. Throws as simplifyMesh.
Mesh simplifyToCount(const Mesh& mesh, size_t targetFaces, SimplifyReport* report = nullptr, bool lockBorder = true);

}  // namespace sprig::organisms
