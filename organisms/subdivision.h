#pragma once
/// Uniform Catmull-Clark refinement of a control mesh: the one file that calls OpenSubdiv.
///
/// A Subdivision holds the topology of every level 0..levels of a control (base) mesh
/// refined uniformly by Catmull-Clark (Catmull & Clark 1978; the ordinary-vertex weights of
/// Fig. 1 of Velho et al., "Procedural shape synthesis on subdivision surfaces", 2002) and
/// moves data from one level to the next: positions and scalars with the subdivision
/// weights (Far::PrimvarRefiner::Interpolate), and limit positions and tangents of the
/// finest level (PrimvarRefiner::Limit). Multiresolution synthesis (organisms/multires.h)
/// adds its detail between these steps: OpenSubdiv 3 has no hierarchical edits.
///
/// Boundaries are interpolated as "edge only" (boundary edges are B-spline curves, every
/// face of an open mesh is kept) and face-varying data linearly at corners only. Child
/// vertices of a level's vertices come first in the next level, so vertex v of level l is
/// vertex v of level l+1 (seeds placed at a vertex keep their index at every finer level).
/// Faces of level l >= 1 are quads, 4^l per control quad; face f of level l is split into
/// faces 4f..4f+3 of level l+1 when every face of level l is a quad.

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/types.h"

namespace sprig::organisms {

/// A polygon mesh: positions and faces (counter-clockwise seen from outside).
struct ControlMesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> faceSizes;     ///< vertices per face, each >= 3
  std::vector<uint32_t> faceVertices;  ///< the faces' vertex indices, concatenated
  /// Number of faces.
  size_t faceCount() const { return faceSizes.size(); }
};

/// The faces of one level, and each vertex's incident faces (compressed rows).
struct LevelTopology {
  std::vector<uint32_t> faceSizes;
  std::vector<uint32_t> faceVertices;
  std::vector<uint32_t> faceOffsets;        ///< first corner of face f in faceVertices; size faces+1
  std::vector<uint32_t> vertexFaceOffsets;  ///< faces of vertex v: vertexFaces[offs[v] .. offs[v+1])
  std::vector<uint32_t> vertexFaces;
  std::vector<uint8_t> boundaryVertex;      ///< 1 when the vertex lies on a boundary edge
  size_t vertexCount() const { return vertexFaceOffsets.empty() ? 0 : vertexFaceOffsets.size() - 1; }
  size_t faceCount() const { return faceSizes.size(); }
};

/// Uniform Catmull-Clark refinement of one control mesh to a fixed number of levels.
/// Immutable after construction; every method is thread-safe.
class Subdivision {
 public:
  /// Refines mesh `levels` times (0 <= levels <= 10). Throws std::invalid_argument when
  /// the topology cannot be refined (OpenSubdiv's message), when an index is out of range
  /// or a face has fewer than 3 vertices. Cost: about 4^levels x the control faces.
  Subdivision(const ControlMesh& mesh, int levels);
  ~Subdivision();
  Subdivision(Subdivision&&) noexcept;
  Subdivision& operator=(Subdivision&&) noexcept;

  /// Number of refinement levels (the finest level's index).
  int levels() const { return int(topology_.size()) - 1; }
  /// Faces, adjacency and boundary flags of level l (0 = the control mesh).
  const LevelTopology& topology(int level) const { return topology_[size_t(level)]; }
  /// Vertices of level l.
  size_t vertexCount(int level) const { return topology_[size_t(level)].vertexCount(); }

  /// Positions of level l (1..levels) from those of level l-1 (vertexCount(l-1) values).
  void interpolate(int level, std::span<const Vec3> coarse, std::span<Vec3> fine) const;
  /// Scalars of level l from those of level l-1, with the same weights.
  void interpolate(int level, std::span<const float> coarse, std::span<float> fine) const;
  /// Limit positions and the two limit tangents (d/du, d/dv) at the finest level's vertices,
  /// from its control points. Any output span may be empty to skip it.
  void limit(std::span<const Vec3> finest, std::span<Vec3> position, std::span<Vec3> du, std::span<Vec3> dv) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<LevelTopology> topology_;
};

}  // namespace sprig::organisms
