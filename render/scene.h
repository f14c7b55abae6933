#pragma once
/// The renderable scene: materials and geometry held in an Embree 3 scene.
///
/// Geometry comes in as neutral types (a lsystem::Skeleton, a Mesh, later compiled
/// BlobTrees) and is turned into Embree geometry here; Embree itself stays behind this
/// interface (only render/*.cpp include it). After commit() the scene is immutable and
/// intersect()/occluded() may be called from any number of threads.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "blobtree/compiled.h"
#include "core/mesh.h"
#include "core/types.h"
#include "lsystem/skeleton.h"
#include "textures/registry.h"

namespace sprig::blobtree {
struct PolygonizeResult;
}

namespace sprig::render {

/// Surface appearance: a diffuse base color with a glossy highlight.
struct Material {
  Vec3 baseColor{0.6f};     ///< linear RGB albedo in [0, 1]
  float roughness = 0.6f;   ///< 0 = mirror-like highlight, 1 = no highlight
  float specular = 0.04f;   ///< highlight strength (reflectance at normal incidence)
  int texture = -1;         ///< texture id for textured models, -1 for none
};

/// A color texture: linear RGB at natural coordinates uv (and world position, for solid
/// textures). Must be thread-safe; the textures module's textures are wrapped into this.
using ColorTexture = std::function<Vec3(Vec2 uv, const Vec3& position)>;

/// How a compiled BlobTree becomes exact Embree user geometry.
struct ImplicitOptions {
  /// Edge of the surface cells (one Embree user primitive each), world units; 0 = automatic:
  /// 1.5x the smallest feature radius, clamped to [diagonal/1000, diagonal/40].
  float cellSize = 0.0f;
  /// Root-finding tolerance (relative to the model's bounds diagonal) and step cap.
  blobtree::TraceOptions trace;
  /// March eight samples at a time with batched field evaluation (the same Lipschitz
  /// guarantee, several times faster); false calls CompiledBlob::intersectCell per cell.
  bool batched = true;
};

/// How a skeleton becomes preview geometry.
struct SkeletonStyle {
  double radiusScale = 1.0;          ///< multiplies every internode radius
  double minRadiusFraction = 0.002;  ///< radius floor as a fraction of the skeleton's bounds diagonal
  Material wood{Vec3(0.30f, 0.20f, 0.12f), 0.7f, 0.03f};  ///< internodes
  Material leaf{Vec3(0.16f, 0.38f, 0.08f), 0.5f, 0.06f};  ///< polygons and named surfaces
  Material fruit{Vec3(0.55f, 0.08f, 0.06f), 0.35f, 0.08f};  ///< spheres
  /// Base colors by turtle color index (`'`); an organ whose index has an entry uses it.
  std::vector<Vec3> palette;
  bool organs = true;  ///< draw organs (polygons, spheres, named surfaces)
};

/// What a ray hit: position, unit normals (not yet facing the ray) and the surface color.
struct SurfaceHit {
  float t = 0;
  Vec3 position{0};
  Vec3 normal{0, 1, 0};           ///< shading normal
  Vec3 geometricNormal{0, 1, 0};  ///< true surface normal, for offsetting secondary rays
  Vec3 color{0.5f};               ///< linear albedo at the hit
  uint32_t material = 0;
  uint32_t geometry = 0;          ///< index of the geometry in the scene (order of add calls)
};

/// Counts of what a scene holds.
struct SceneStats {
  size_t curveSegments = 0;  ///< skeleton internodes (round linear curve segments)
  size_t triangles = 0;      ///< mesh and leaf triangles
  size_t spheres = 0;        ///< sphere organs
  size_t implicitCells = 0;  ///< surface cells of implicit models (Embree user primitives)
};

/// Materials and geometry behind an Embree 3 device and scene.
class Scene {
 public:
  Scene();
  ~Scene();
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  /// Adds a material; returns its id.
  uint32_t addMaterial(const Material& m);
  /// Material `id`; throws std::out_of_range for an unknown id.
  const Material& material(uint32_t id) const;

  /// Adds a skeleton: internodes as round linear curves (tapered cones; an internode that
  /// continues its parent's end shares the joint), polygons fan-triangulated, spheres as
  /// Embree sphere points, named surfaces as small diamond leaves. Returns geometry ids added.
  std::vector<uint32_t> addSkeleton(const lsystem::Skeleton& skeleton, const SkeletonStyle& style = {});

  /// Adds a triangle mesh with one material (per-triangle `mesh.materials`, when present,
  /// name scene material ids instead). Vertex normals give smooth shading, vertex colors
  /// replace the material's base color. Returns the geometry id.
  uint32_t addMesh(const Mesh& mesh, uint32_t material);

  /// Registers a texture; returns its id. Ids are what blob primitives' TextureAttr::textureId
  /// and Material::texture refer to.
  uint32_t addTexture(ColorTexture texture);

  /// Registers every texture of registry, in id order (the registry is shared, not copied);
  /// returns the scene id of the registry's texture 0. Into an empty texture table, the
  /// scene ids equal the registry ids that blob primitives carry.
  uint32_t addTextures(std::shared_ptr<const textures::TextureRegistry> registry);

  /// Adds a compiled BlobTree as exact implicit geometry: one Embree user primitive per
  /// surface cell (bounds = the cell box); intersection and occlusion rays call
  /// CompiledBlob::intersectCell, which marches with the cell's local Lipschitz bound.
  /// Hit colors blend the primitives' textures by field weight (attributeColor); blobs
  /// without textures use the material's base color. Returns the geometry id.
  uint32_t addImplicit(const blobtree::CompiledBlob& blob, uint32_t material, const ImplicitOptions& options = {});

  /// Adds a polygonized BlobTree (mesh mode): triangles with the mesh's normals, and vertex
  /// colors from the per-vertex attributes through the same texture blend as exact mode.
  uint32_t addPolygonized(const blobtree::PolygonizeResult& result, uint32_t material);

  /// Color of blended attributes at p: Σ wᵢ·Tᵢ(uv, p) over the attribute's textures
  /// (weights from the field, seeds' texturing); the material's base color for a texture
  /// id without a registered texture, or when there is none.
  Vec3 attributeColor(const blobtree::Attributes& attributes, const Vec3& p, const Material& material) const;

  /// Builds the acceleration structure. Throws std::runtime_error on an Embree error.
  void commit();

  /// Bounds of everything added (implicit models: their surface cells, shrunk by interval
  /// bounds to nearly the surface).
  Box3 bounds() const;
  /// What the scene holds.
  SceneStats stats() const;

  /// Closest hit along origin + t*direction for t in [tnear, tfar], or nothing.
  std::optional<SurfaceHit> intersect(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const;
  /// True when anything lies along origin + t*direction for t in [tnear, tfar].
  bool occluded(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const;

  struct Impl;  ///< Embree state (render/detail/scene_impl.h)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace sprig::render
