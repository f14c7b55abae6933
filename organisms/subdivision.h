#pragma once
/// Uniform Catmull-Clark or Loop refinement of a control mesh: the one file that calls OpenSubdiv.
///
/// A Subdivision holds the topology of every level 0..levels of a control (base) mesh
/// refined uniformly by Catmull-Clark (Catmull & Clark 1978; the ordinary-vertex weights of
/// Fig. 1 of Velho et al., "Procedural shape synthesis on subdivision surfaces", 2002) or,
/// for triangle meshes, by Loop (Loop 1987, "Smooth subdivision surfaces based on
/// triangles"), and moves data from one level to the next: positions and scalars with the
/// subdivision weights (Far::PrimvarRefiner::Interpolate), varying and face-varying data
/// linearly, and limit positions and tangents of the finest level (PrimvarRefiner::Limit).
/// Multiresolution synthesis (organisms/multires.h) adds its detail between these steps:
/// OpenSubdiv 3 has no hierarchical edits.
///
/// Boundaries are interpolated as "edge only" (boundary edges are B-spline curves, every
/// face of an open mesh is kept). Crease edges are infinitely sharp (Hoppe et al. 1994,
/// "Piecewise smooth surface reconstruction", as OpenSubdiv's Sdc crease rules): their
/// points follow the crease curve's cubic B-spline, and a vertex where three or more
/// creases meet is a corner and stays. The face-varying channel is interpolated linearly
/// everywhere (FVAR_LINEAR_ALL): a value at a vertex stays, one on an edge is the mean of
/// its ends' on the same side. Child vertices of a level's vertices come first in the next
/// level, so vertex v of level l is vertex v of level l+1 (seeds placed at a vertex keep
/// their index at every finer level). Faces of level l >= 1 are quads, 4^l per control
/// quad (Catmull-Clark), or triangles, 4^l per control triangle (Loop); face f of level l
/// is split into faces 4f..4f+3 of level l+1 when every face of level l is a quad (or,
/// with Loop, always).

#include <array>
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
  /// With a face-varying channel: per corner (parallel to faceVertices), its value's index.
  std::vector<uint32_t> faceVaryingIndices;
  size_t faceVaryingCount = 0;              ///< values of the face-varying channel
  size_t vertexCount() const { return vertexFaceOffsets.empty() ? 0 : vertexFaceOffsets.size() - 1; }
  size_t faceCount() const { return faceSizes.size(); }
};

/// The subdivision rules.
enum class SubdivisionScheme : uint8_t {
  CatmullClark,  ///< any polygons; faces of level >= 1 are quads
  Loop,          ///< triangles only; each triangle into four
};

/// How a Subdivision refines its control mesh.
struct SubdivisionOptions {
  SubdivisionScheme scheme = SubdivisionScheme::CatmullClark;
  /// Infinitely sharp crease edges, each as its two control vertices (an edge of the mesh).
  std::vector<std::array<uint32_t, 2>> creases;
  /// An optional face-varying channel: per control face corner (parallel to
  /// ControlMesh::faceVertices) the index of its value, 0 .. faceVaryingCount-1; corners
  /// around a vertex with the same index share the value, so an edge whose ends' indices
  /// differ across it is a seam. Empty: no channel.
  std::vector<uint32_t> faceVaryingIndices;
  size_t faceVaryingCount = 0;  ///< values of the channel (> every index)
};

/// What an interpolate call moves to the next level, and by which weights.
enum class Primvar : uint8_t {
  Vertex,       ///< per vertex, with the scheme's weights (a position)
  Varying,      ///< per vertex, linearly: a vertex's value stays, an edge point takes its ends' mean
  FaceVarying,  ///< per value of the face-varying channel, linearly (FVAR_LINEAR_ALL)
};

/// Uniform Catmull-Clark or Loop refinement of one control mesh to a fixed number of levels.
/// Immutable after construction; every method is thread-safe.
class Subdivision {
 public:
  /// Refines mesh `levels` times (0 <= levels <= 10). Throws std::invalid_argument when
  /// the topology cannot be refined (OpenSubdiv's message), when an index is out of range,
  /// a face has fewer than 3 vertices (Loop: is not a triangle), a crease is not an edge
  /// or the face-varying channel does not fit. Cost: about 4^levels x the control faces.
  Subdivision(const ControlMesh& mesh, int levels, const SubdivisionOptions& options = {});
  ~Subdivision();
  Subdivision(Subdivision&&) noexcept;
  Subdivision& operator=(Subdivision&&) noexcept;

  /// Number of refinement levels (the finest level's index).
  int levels() const { return int(topology_.size()) - 1; }
  /// Faces, adjacency and boundary flags of level l (0 = the control mesh).
  const LevelTopology& topology(int level) const { return topology_[size_t(level)]; }
  /// Vertices of level l.
  size_t vertexCount(int level) const { return topology_[size_t(level)].vertexCount(); }
  /// The face of level l-1 that face f of level l (1..levels) is a part of. Throws
  /// std::invalid_argument when level or face is out of range.
  uint32_t parentFace(int level, uint32_t face) const;

  /// Positions of level l (1..levels) from those of level l-1 (vertexCount(l-1) values).
  void interpolate(int level, std::span<const Vec3> coarse, std::span<Vec3> fine) const;
  /// Scalars of level l from those of level l-1, with the same weights.
  void interpolate(int level, std::span<const float> coarse, std::span<float> fine) const;
  /// `width` floats per item (vertex, or face-varying value) of level l from those of level
  /// l-1, interleaved, with kind's weights. Throws std::invalid_argument on a wrong level or
  /// array size.
  void interpolate(int level, Primvar kind, std::span<const float> coarse, std::span<float> fine, size_t width) const;
  /// Limit positions and the two limit tangents (d/du, d/dv) at the finest level's vertices,
  /// from its control points. Any output span may be empty to skip it.
  void limit(std::span<const Vec3> finest, std::span<Vec3> position, std::span<Vec3> du, std::span<Vec3> dv) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<LevelTopology> topology_;
};

}  // namespace sprig::organisms
