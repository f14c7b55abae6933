#pragma once
/// Clean-up of polygonized surfaces: debris removal and normals that agree with the winding.
///
/// A polygonized implicit surface (blobtree/polygonize.h) is closed and consistently wound,
/// but it can carry debris: tiny closed components beside the model where the field
/// brushes 0.5 (specks, positive volume) and tiny inward-facing shells inside a wall
/// (voids, negative volume), and vertex normals from the field's gradient that point
/// against the winding where the gradient of a CSG operand or a flat blend disagrees with
/// the surface actually meshed. cleanMesh removes components whose enclosed volume is a
/// tiny fraction of the model's and re-derives the normals that disagree with the winding.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/mesh.h"

namespace sprig {

/// Options of cleanMesh().
struct MeshCleanOptions {
  /// A connected component whose |enclosed volume| is below this fraction of the model's
  /// volume (the sum of the signed volumes of all components) is removed: specks outside
  /// (volume > 0) and voids inside (volume < 0). 0 keeps every component.
  double minVolumeFraction = 1e-4;
  /// Replace every vertex normal that points against the winding normal of one of its
  /// triangles (negative dot product) by the area-weighted winding normal of its triangles
  /// (unit length). A triangle can still face against that normal where the surface folds
  /// by more than 90 degrees within one vertex's triangles (facesAgainstAfter counts them).
  bool fixNormals = true;
};

/// What cleanMesh() found and changed.
struct MeshCleanReport {
  size_t componentsBefore = 0;   ///< connected components (triangles sharing a vertex) before
  size_t componentsAfter = 0;    ///< and after the removal
  size_t specks = 0;             ///< removed components of positive volume
  size_t voids = 0;              ///< removed components of negative volume
  size_t removedTriangles = 0;   ///< triangles of the removed components
  double modelVolume = 0;        ///< signed volume of the whole mesh before cleaning
  size_t facesAgainstBefore = 0; ///< facesAgainstWinding() before
  size_t facesAgainstAfter = 0;  ///< and after
  size_t fixedNormals = 0;       ///< vertex normals replaced
};

/// Component id (0..count-1, numbered in order of first triangle) of every triangle;
/// triangles are connected when they share a vertex index. count receives the number.
std::vector<uint32_t> triangleComponents(const Mesh& mesh, size_t* count = nullptr);

/// Number of triangles with at least one vertex normal n such that n · (the triangle's
/// winding normal) < 0. 0 when the mesh has no normals. O(T).
size_t facesAgainstWinding(const Mesh& mesh);

/// Degenerate triangles of removeDegenerateTriangles(), by cause.
struct DegenerateReport {
  size_t repeatedIndex = 0;  ///< two corners name the same vertex
  size_t zeroArea = 0;       ///< three distinct vertices, collinear or coincident (zero area)
  size_t total() const { return repeatedIndex + zeroArea; }
};

/// Removes degenerate triangles in place: two equal vertex indices, or zero area (the cross
/// product of two edges, computed in double from the float positions, is exactly zero).
/// The coincident corners of a zero-area triangle become one vertex (the lower index, in
/// every triangle), so removing it leaves no slit open in a closed surface. Keeps the order
/// of the other triangles and their Mesh::materials; keeps every vertex (an unused vertex
/// is harmless to the formats). kept, when given, receives the original index
/// of each remaining triangle. O(T).
DegenerateReport removeDegenerateTriangles(Mesh& mesh, std::vector<size_t>* kept = nullptr);

/// Removes debris components and fixes normals in place (see MeshCleanOptions); keeps the
/// order of the remaining vertices and triangles and every per-vertex and per-triangle
/// array. Deterministic. O(T + V).
MeshCleanReport cleanMesh(Mesh& mesh, const MeshCleanOptions& options = {});

}  // namespace sprig
