#pragma once
/// The renderable scene: materials and geometry held in an Embree 3 scene.
///
/// Geometry comes in as neutral types (render/geometry.h: curves, spheres, meshes, compiled
/// BlobTrees, each with its own texture table) and is turned into Embree geometry here;
/// Embree itself stays behind this interface (only render/*.cpp include it). After commit() the scene is immutable and
/// intersect()/occluded() may be called from any number of threads.

#include <algorithm>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "blobtree/compiled.h"
#include "core/mesh.h"
#include "core/shapes.h"
#include "core/types.h"
#include "render/camera.h"
#include "render/geometry.h"
#include "textures/registry.h"

namespace sprig::blobtree {
struct PolygonizeResult;
}

namespace sprig::render {

/// What a ray hit: position, unit normals (not yet facing the ray) and the surface color.
struct SurfaceHit {
  float t = 0;
  Vec3 position{0};
  Vec3 normal{0, 1, 0};           ///< shading normal
  Vec3 geometricNormal{0, 1, 0};  ///< true surface normal, for offsetting secondary rays
  Vec3 color{0.5f};               ///< linear albedo at the hit
  /// The hit's own (roughness, specular, metallic) when ownSurface (a mesh's per-vertex
  /// surfaces, interpolated); otherwise the material's apply.
  bool ownSurface = false;
  Vec3 surface{0};
  uint32_t material = 0;
  uint32_t geometry = 0;          ///< index of the geometry in the scene (order of add calls)
  /// Coverage of a widened thin curve at the hit (true width / drawn width), 1 for
  /// everything else. Below 1 the renderer blends this hit over what lies behind it,
  /// traced again from `behind` (past the curve's drawn tube and what it stands for).
  float opacity = 1.0f;
  float behind = 0.0f;
  /// Triangles with vertex normals: the move from `position` to the point above it on the
  /// smooth surface the vertex normals describe, for the side the normals face
  /// (terminatorLift[0]) and the other side ([1]); zero elsewhere (Scene::terminatorLift).
  std::array<Vec3, 2> terminatorLift{Vec3(0), Vec3(0)};
};

/// Hanika's shadow-terminator offset ("Hacking the shadow terminator", Ray Tracing Gems II,
/// 2021, ch. 4): the point p = Σ bᵢ·pᵢ of a triangle with unit vertex normals nᵢ is
/// projected onto each vertex's tangent plane where it lies below it, and the projections
/// are blended by the barycentric weights b: the returned move is Σ bᵢ·max(0, −(p − pᵢ)·nᵢ)·nᵢ.
/// Zero at the corners, and wherever the triangle bulges above its vertices' planes.
Vec3 terminatorLift(const std::array<Vec3, 3>& corners, const std::array<Vec3, 3>& normals, const Vec3& barycentric);

/// How wide a pixel is along the camera's view: a segment thinner than `minPixels` pixels
/// is drawn that wide with opacity true width / drawn width.
struct PixelFootprint {
  Vec3 eye{0};                 ///< camera position
  Vec3 forward{0, 0, -1};      ///< unit view direction
  float pixelPerDepth = 0.0f;  ///< world size of one pixel at unit depth along forward
  float minPixels = 1.0f;      ///< minimum drawn diameter, pixels
  /// The smallest drawn radius at world point p.
  float minRadius(const Vec3& p) const {
    return 0.5f * minPixels * pixelPerDepth * std::max(glm::dot(p - eye, forward), 0.0f);
  }
};

/// Counts of what a scene holds.
struct SceneStats {
  size_t curveSegments = 0;  ///< skeleton internodes (round linear curve segments)
  size_t triangles = 0;      ///< mesh and leaf triangles
  size_t spheres = 0;        ///< sphere organs
  size_t implicitCells = 0;  ///< surface cells of implicit models (those not free are Embree user primitives)
  /// Of those, cells proven free of the surface and left out (blobtree::FreeSubCells).
  size_t implicitFreeCells = 0;
  float implicitCellSize = 0;  ///< the largest edge of those cells, world units
  size_t implicitTapes = 0;  ///< distinct pruned tapes of those cells (ImplicitOptions::prunedTapes)
  size_t implicitTapeNodes = 0;  ///< nodes of those tapes, summed over the cells
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

  /// Adds every part of geometry in order, each with a material of its own and its texture
  /// table (part texture ids index that table). Returns the geometry ids, one per part.
  std::vector<uint32_t> add(const Geometry& geometry);

  /// Minimum drawn width of thin geometry (the hair approach): after this call, curve
  /// segments narrower than minPixels pixels as seen by camera in a width x height image are
  /// widened to minPixels with opacity true width / drawn width, so sub-pixel twigs keep
  /// their coverage instead of breaking into dots; implicit and polygonized parts draw
  /// their thinAxes that way. Call before adding geometry (throws std::logic_error after);
  /// minPixels <= 0 turns it off. Scenes without a footprint draw curves as they are.
  /// The camera's pixel also sets the texel footprint of image maps (MeshPart::image: the
  /// choice of their magnification or minification filter), whatever minPixels is.
  void setPixelFootprint(const Camera& camera, int width, int height, float minPixels = kThinMinPixels);
  /// Implicit models added afterwards size their cells (ImplicitOptions::followPixels) for
  /// camera's pixel in an image height rows tall instead of the footprint's camera: a close-up
  /// traced in the cells of a distant camera (model/model.h renderInset). The surface is the
  /// same (the tracer is exact in a cell of any size); coarser cells cost less to build and
  /// more per ray. Call before adding geometry (throws std::logic_error after).
  void setCellFootprint(const Camera& camera, int height);
  /// The camera samples the scene is expected to be rendered with: spp samples per pixel of
  /// a width x height image seen by camera. Implicit parts added afterwards prove the free
  /// sub-cells (ImplicitOptions::freeSubCells) of the cells that can expect at least
  /// ImplicitOptions::freeSubCellsEager of them when the cells are made, the others when
  /// rays come; without an expectation every cell waits for its rays. Only the cost
  /// changes: the image is the same whatever is expected. Call before adding geometry
  /// (throws std::logic_error after); width, height or spp < 1 clears the expectation.
  void setExpectedSamples(const Camera& camera, int width, int height, int spp);
  /// false: every implicit part added afterwards traces the whole tape in each cell, whatever
  /// its ImplicitOptions::prunedTapes says (the reference the pruned tapes are checked
  /// against). Default: prunedTapesDefault().
  void setPrunedTapes(bool on);
  /// The process-wide default of setPrunedTapes for scenes constructed afterwards (true;
  /// the global flag `sprig --full-tape` sets false, to compare images with the reference).
  static void setPrunedTapesDefault(bool on);
  static bool prunedTapesDefault();
  /// Default minimum width of thin geometry, pixels.
  static constexpr float kThinMinPixels = 2.0f;

  /// Adds tapered round curves (Embree round linear curves) with one material.
  uint32_t addCurves(const CurveSet& curves, uint32_t material);
  /// Adds the segments of axes that are thinner than the footprint's minimum width (mean
  /// radius) as widened transparent curves standing for geometry already added (hits of
  /// other geometry inside their tubes are skipped). Nothing without a footprint; returns
  /// the geometry id, or nothing when no segment is thin.
  std::optional<uint32_t> addThinAxes(const CurveSet& axes, uint32_t material);

  /// Adds spheres (Embree sphere points), each with its own colour. Returns the geometry id.
  uint32_t addSpheres(const SphereSet& spheres, uint32_t material);

  /// Adds a triangle mesh with one material (per-triangle `mesh.materials`, when present,
  /// name scene material ids instead). Vertex normals give smooth shading, vertex colors
  /// replace the material's base color. Returns the geometry id.
  /// triangleColors, when not empty (one per triangle), replace both. vertexSurfaces, when
  /// not empty (one per vertex), replace the material's (roughness, specular, metallic).
  uint32_t addMesh(const Mesh& mesh, uint32_t material, const std::vector<Vec3>& triangleColors = {},
                   const std::vector<Vec3>& vertexSurfaces = {});

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
  /// textures: the part's texture table (scene ids textureBase..textureBase+textureCount-1);
  /// the default is the scene's whole table. Textures, or a material whose ridge tilts
  /// normals, need result's attributes (PolygonizeOptions::VertexData::Blend): without them
  /// it throws std::invalid_argument.
  uint32_t addPolygonized(const blobtree::PolygonizeResult& result, uint32_t material, uint32_t textureBase = 0,
                          uint32_t textureCount = kAllTextures);

  /// Color of blended attributes at p: Σ wᵢ·Tᵢ(uv, p) over the attribute's textures at the
  /// field-blended uv, or with material.textureLayers Σ wᵢ·T_idᵢ(uvᵢ, p) over its layers
  /// (the heaviest contributing primitives, each at its own natural uv); weights from the
  /// field (tree paper §3.7); times 1 − material.ridge.darkness(contact, p). The material's
  /// base color for a texture id without a registered texture, or when there is none.
  /// textureBase/textureCount select a part's texture table (default: the scene's whole table).
  Vec3 attributeColor(const blobtree::Attributes& attributes, const Vec3& p, const Material& material,
                      uint32_t textureBase = 0, uint32_t textureCount = kAllTextures) const;

  /// textureCount meaning "every texture of the scene" (geometry added without a table).
  static constexpr uint32_t kAllTextures = 0xffffffffu;

  /// Builds the acceleration structure. Throws std::runtime_error on an Embree error.
  void commit();

  /// The labels of every geometry added (Geometry::labels), in order; renderImage writes
  /// them over the picture.
  const std::vector<TextLabel>& labels() const;

  /// Bounds of everything added (implicit models: their surface cells, shrunk by interval
  /// bounds to nearly the surface).
  Box3 bounds() const;
  /// What the scene holds.
  SceneStats stats() const;
  /// True when this scene is the one setPixelFootprint(camera, width, height) would have
  /// built from the same geometry: nothing added followed the footprint's camera (widened
  /// curves, thin-axis stand-ins, image-mapped meshes' texture filtering), or only implicit
  /// models' cell sizes did (ImplicitOptions::followPixels) and camera gives each the same
  /// cell (render::pixelCellSize). Animation turntables reuse such a scene.
  bool servesCamera(const Camera& camera, int width, int height) const;

  /// Closest hit along origin + t*direction for t in [tnear, tfar], or nothing. A ray
  /// Embree cannot trace (a coordinate of origin or direction not finite or beyond 1.8e18,
  /// tnear negative or NaN, tfar NaN) misses.
  std::optional<SurfaceHit> intersect(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const;
  /// True when anything lies along origin + t*direction for t in [tnear, tfar] (false for
  /// a ray intersect() calls untraceable).
  bool occluded(const Vec3& origin, const Vec3& direction, float tnear, float tfar) const;

  struct Impl;  ///< Embree state (render/detail/scene_impl.h)

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace sprig::render
