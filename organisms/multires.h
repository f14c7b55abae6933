#pragma once
/// Multiresolution synthesis on a Catmull-Clark hierarchy (Velho, Perlin, Ying, Biermann,
/// "Procedural shape synthesis on subdivision surfaces", 2002, §2.2-3, Fig. 2 and 4).
///
/// Synthesis: P_0 is the control mesh (plus level-0 detail); for l = 1..L,
///   S_l = subdivide(P_{l-1}),   frames F_l from S_l,   P_l = S_l + F_l d_l,
/// where d_l is the level's detail in the local frame (tangent, bitangent, normal) of the
/// coarser surface's refinement, so a detail moves with the surface: a rotated base gives
/// the rotated result. A scalar channel h (the planet's height field, §6.3) is refined the
/// same way: h_l = subdivide(h_{l-1}) + s_l.
///
/// The detail of a level is the sum of the detail procedures of a shape (§4: F(p, l)); two
/// shapes on the same base blend per level (§6, Burt's multi-scale blend):
///   d_l = (1 - alpha_l) d^A_l + alpha_l d^B_l,
/// with alpha_l a transition whose width can shrink with the level. Local modification
/// (§5.2) multiplies the detail of chosen levels by a gain that falls off with the
/// topological distance from a point (cubic drop-off). Procedures see the evolving surface
/// S_l, its frames, the undetailed reference surface at the same level, the level and the
/// animation time (§3).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "core/types.h"
#include "organisms/subdivision.h"

namespace sprig::organisms {

/// An orthonormal local frame: tangent, bitangent, normal (outward for a CCW mesh).
struct Frame {
  Vec3 t{1, 0, 0}, b{0, 1, 0}, n{0, 0, 1};
  /// Local components (along t, b, n) to a world vector.
  Vec3 toWorld(const Vec3& local) const { return local.x * t + local.y * b + local.z * n; }
  /// A world vector's local components.
  Vec3 toLocal(const Vec3& world) const { return {glm::dot(world, t), glm::dot(world, b), glm::dot(world, n)}; }
};

/// Frames of a level's vertices from its positions: the normal is the sum of the incident
/// faces' (Newell) area normals, normalized; the tangent is the direction to the next vertex
/// of the vertex's first incident face, made orthogonal to the normal (a choice fixed by the
/// topology, so it rotates with the mesh). Parallel; deterministic.
void computeFrames(const LevelTopology& topo, std::span<const Vec3> positions, std::span<Frame> frames);

/// Each vertex's neighbours along edges (compressed rows), for topological distances.
struct VertexNeighbours {
  std::vector<uint32_t> offsets;  ///< size vertices+1
  std::vector<uint32_t> items;
};
/// Edge neighbours of every vertex of a level.
VertexNeighbours vertexNeighbours(const LevelTopology& topo);

/// What a detail procedure sees of one level.
struct LevelView {
  int level = 0;     ///< 0 = the control mesh, L = the finest
  double time = 1;   ///< animation time in [0, 1] (§3)
  const Subdivision* subdivision = nullptr;
  const LevelTopology* topology = nullptr;
  std::span<const Vec3> smooth;     ///< S_l: the coarser level subdivided, before this level's detail
  std::span<const Frame> frames;    ///< F_l, from smooth
  std::span<const Vec3> reference;  ///< the base surface without any detail, at this level
  /// Mean edge length of the level's reference mesh (the size of one sample, §6).
  float sampleSize = 0;
};

/// Detail a level receives: offsets in the vertices' local frames, and scalar detail.
struct LevelDetail {
  std::vector<Vec3> offset;  ///< per vertex: (tangent, bitangent, normal) components
  std::vector<float> scalar;  ///< per vertex (only filled when some procedure writes scalars)
  /// Zeroes both arrays for n vertices (scalars only when withScalar).
  void reset(size_t n, bool withScalar);
};

/// One synthesis run of a procedure (may keep state between levels, e.g. seeds).
class DetailRun {
 public:
  virtual ~DetailRun() = default;
  /// Adds this procedure's detail at view.level to out (out is sized for the level).
  virtual void add(const LevelView& view, LevelDetail& out) = 0;
};

/// A detail procedure F(p, l) (§4): immutable configuration; start() makes one run.
class DetailProcedure {
 public:
  virtual ~DetailProcedure() = default;
  /// The procedure's species-file name ("rock", "berry", ...).
  virtual std::string name() const = 0;
  /// True when it writes the scalar channel instead of (or besides) offsets.
  virtual bool writesScalar() const { return false; }
  /// A fresh run over subdivision (seeds are drawn from the procedure's own seed).
  virtual std::unique_ptr<DetailRun> start(const Subdivision& subdivision) const = 0;
};

/// The detail procedures of one shape, summed.
using DetailSet = std::vector<std::shared_ptr<const DetailProcedure>>;

/// Where a blend takes shape B (alpha 1) instead of A (alpha 0), per level (§6).
class AlphaField {
 public:
  virtual ~AlphaField() = default;
  /// Alpha of every vertex of view.level (alpha.size() == vertices of the level), in [0, 1].
  virtual void evaluate(const LevelView& view, std::span<float> alpha) const = 0;
};

/// Alpha from a plane n·p = offset (+ speed·time), p the reference position: a smoothstep
/// transition of width c / 2^(l-1) at level l >= 1 ("sharp", Fig. 12 and 13a) or c at every
/// level ("soft", Fig. 13b); width 0 = a hard switch. Alpha is 1 on the side n points to.
struct PlaneAlpha final : AlphaField {
  Vec3 normal{1, 0, 0};
  float offset = 0;
  float speed = 0;  ///< offset moves by speed * time
  float width = 0.5f;
  bool sharp = true;
  /// Width of the transition at level l.
  float widthAt(int level) const;
  void evaluate(const LevelView& view, std::span<float> alpha) const override;
};

/// Alpha from any function of the reference position, level and time (a procedure or a
/// painted map looked up through the base's coordinates).
struct FunctionAlpha final : AlphaField {
  std::function<float(const Vec3& reference, int level, double time)> f;
  void evaluate(const LevelView& view, std::span<float> alpha) const override;
};

/// Alpha from a painted map: a value m in [0, 1] per control vertex (the base mesh's vertex
/// paint), carried to level l by the same Catmull-Clark refinement as the surface. The
/// painted edge is where m crosses 1/2; alpha_l = smoothstep(1/2 + (m_l - 1/2) 2^(l-1) / width)
/// ("sharp": the transition narrows by half per level, as Burt's masks do, §6) or
/// smoothstep(1/2 + (m_l - 1/2) / width) at every level ("soft").
struct PaintedAlpha final : AlphaField {
  std::vector<float> control;  ///< m per control vertex
  float width = 1;
  bool sharp = true;
  void evaluate(const LevelView& view, std::span<float> alpha) const override;
};

/// Local detail modification (§5.2): the detail of level l within `radius` (topological
/// distance: edge hops at that level times its sample size) of the surface vertex nearest
/// `center` is multiplied by 1 + (gain_l - 1) k(d / radius), k(x) = 1 - 3x^2 + 2x^3.
struct Modification {
  Vec3 center{0.0f};
  float radius = 0.1f;
  std::vector<float> gains;  ///< gains[l] for level l; levels beyond the list keep gain 1
};

/// Options of one synthesis.
struct SynthesisOptions {
  double time = 1;
  /// Keep every level's positions and world-space detail (tests, figures of levels).
  bool keepLevels = false;
};

/// The synthesized surface.
struct SynthesisResult {
  std::vector<Vec3> positions;  ///< P_L: the finest level's control points
  std::vector<float> scalar;    ///< h_L (empty unless a procedure writes scalars)
  std::vector<float> alpha;     ///< the finest level's blend alpha (empty without a blend)
  /// With keepLevels: P_l, S_l and the world-space detail P_l - S_l of every level.
  std::vector<std::vector<Vec3>> levelPositions, levelSmooth, levelDetail;
  std::vector<std::vector<float>> levelAlpha;
};

/// Everything synthesis combines over one base.
struct SynthesisInput {
  DetailSet shapeA;                          ///< the detail of the shape (alpha 0)
  DetailSet shapeB;                          ///< the second shape of a blend (alpha 1)
  std::shared_ptr<const AlphaField> alpha;   ///< null: no blend (shapeB unused)
  std::vector<Modification> modifications;
};

/// Runs synthesis from the control positions (subdivision's level 0 mesh) to its finest
/// level. Deterministic at any thread count. Cost: per level, one interpolation, frames,
/// and the procedures' cost; O(vertices of the finest level) overall.
SynthesisResult synthesize(const Subdivision& subdivision, std::span<const Vec3> control, const SynthesisInput& input,
                           const SynthesisOptions& options = {});

/// Refines the control positions without detail: the reference surface of every level.
std::vector<std::vector<Vec3>> referenceLevels(const Subdivision& subdivision, std::span<const Vec3> control);

/// The finest level as a triangle mesh of its limit surface: limit positions and unit limit
/// normals (the cross product of the limit tangents, oriented like the faces) at the
/// finest vertices, each face fan-split (quads along their shorter diagonal). Closed when
/// the control mesh is closed. Needs subdivision.levels() >= 1.
Mesh limitMesh(const Subdivision& subdivision, std::span<const Vec3> finest);

/// The finest level's control points as a triangle mesh (no limit evaluation; normals
/// from the faces), for tests and level figures.
Mesh controlMeshOf(const LevelTopology& topo, std::span<const Vec3> positions);

/// Index of the position nearest p (the first on ties). O(n).
uint32_t nearestPosition(std::span<const Vec3> positions, const Vec3& p);

/// Mean edge length of a level's mesh with the given positions.
float meanEdgeLength(const LevelTopology& topo, std::span<const Vec3> positions);

}  // namespace sprig::organisms
