#pragma once
/// Indexed triangle mesh shared by every geometry producer and the renderer.
///
/// Per-vertex arrays are either empty or the same length as positions. Triangles are
/// counter-clockwise seen from outside (normals point out).

#include <cstdint>
#include <vector>

#include "core/types.h"

namespace sprig {

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;     ///< optional, unit length
  std::vector<Vec2> uvs;         ///< optional texture coordinates
  std::vector<Vec3> colors;      ///< optional linear RGB
  std::vector<glm::uvec3> triangles;
  std::vector<uint32_t> materials;  ///< optional, one id per triangle

  size_t vertexCount() const { return positions.size(); }
  size_t triangleCount() const { return triangles.size(); }
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
  bool closed() const { return boundaryEdges == 0; }
  bool manifold() const { return nonManifoldEdges == 0 && inconsistentEdges == 0; }
};

/// Counts boundary, non-manifold and inconsistently oriented edges. O(T log T).
MeshTopology analyzeTopology(const Mesh& mesh);

/// Signed volume (divergence theorem); positive for a closed, outward-oriented mesh.
double signedVolume(const Mesh& mesh);

}  // namespace sprig
