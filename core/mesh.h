#pragma once
/// Indexed triangle mesh shared by every geometry producer and the renderer.
///
/// Per-vertex arrays are either empty or the same length as positions. Triangles are
/// counter-clockwise seen from outside (normals point out).

#include <cstdint>
#include <vector>

#include "core/types.h"

namespace sprig {

/// An indexed triangle mesh; optional per-vertex arrays are empty or one entry per position.
struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;     ///< optional, unit length
  std::vector<Vec2> uvs;         ///< optional texture coordinates
  std::vector<Vec3> colors;      ///< optional linear RGB
  std::vector<glm::uvec3> triangles;
  std::vector<uint32_t> materials;  ///< optional, one id per triangle

  /// Number of vertices (positions).
  size_t vertexCount() const { return positions.size(); }
  /// Number of triangles.
  size_t triangleCount() const { return triangles.size(); }
  /// Bounding box of the positions (empty box for an empty mesh).
  Box3 bounds() const;
  /// Appends other, offsetting its indices. Optional arrays are kept only if both have them
  /// (or this mesh is empty).
  void append(const Mesh& other);
};

/// Edge statistics of a triangle mesh, for closedness and manifoldness checks.
struct MeshTopology {
  size_t boundaryEdges = 0;      ///< edges used by one triangle
  size_t nonManifoldEdges = 0;   ///< edges used by more than two triangles
  size_t inconsistentEdges = 0;  ///< edges two triangles traverse in the same direction
  size_t degenerateTriangles = 0;
  /// No boundary edges.
  bool closed() const { return boundaryEdges == 0; }
  /// Every edge has at most two triangles, traversed in opposite directions.
  bool manifold() const { return nonManifoldEdges == 0 && inconsistentEdges == 0; }
};

/// Counts boundary, non-manifold and inconsistently oriented edges. O(T log T).
MeshTopology analyzeTopology(const Mesh& mesh);

/// Signed volume (divergence theorem); positive for a closed, outward-oriented mesh.
double signedVolume(const Mesh& mesh);

}  // namespace sprig
