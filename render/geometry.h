#pragma once
/// Neutral geometry: what a model hands the renderer.
///
/// A Geometry is a list of parts, each a curve set, sphere set, triangle mesh, compiled
/// BlobTree (exact) or polygonized BlobTree (mesh mode), with its own material and its own
/// texture table. Part texture ids (a material's `texture`, a blob primitive's texture
/// attribute) index that part's table, so parts from different models never share ids.
/// Scene::add turns a Geometry into Embree geometry; nothing here names Embree, a skeleton
/// or a species.

#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "blobtree/compiled.h"
#include "core/mesh.h"
#include "core/shapes.h"
#include "core/types.h"
#include "textures/ridge.h"

namespace sprig::blobtree {
struct PolygonizeResult;
}

namespace sprig::render {

/// Surface appearance: a diffuse base color with a glossy highlight.
struct Material {
  Vec3 baseColor{0.6f};     ///< linear RGB albedo in [0, 1]
  float roughness = 0.6f;   ///< 0 = mirror-like highlight, 1 = no highlight
  float specular = 0.04f;   ///< highlight strength (reflectance at normal incidence)
  /// 0 = dielectric, 1 = metal: the diffuse lobe is scaled by 1 − metallic and the
  /// highlight's reflectance is lerp(specular, base colour, metallic) (docs/RENDERING.md).
  float metallic = 0.0f;
  int texture = -1;         ///< texture id for textured models, -1 for none
  /// Textured blobs: colour each contributing primitive's texture at its own natural uv
  /// and blend the colours by field weight (blobtree::Attributes::layers; trees' bark, so
  /// furrows follow each branch). false: each texture once at the field-blended uv.
  bool textureLayers = false;
  /// Textured blobs along a PCM seam (the branch bark ridge; blobtree::Attributes::contact
  /// is 1 on the seam): the colour is multiplied by 1 − ridge.darkness(contact, p) (compressed
  /// bark on the crest, folds of bunched bark parallel to it), and the shading normal is
  /// tilted by the ridge's relief (ridge.shadingNormal). The default changes nothing.
  textures::RidgeShade ridge;
  /// Coarse meshes with smooth vertex normals (a tetrahedral solid's surface): shadow and
  /// sky rays leave from the point lifted off the flat triangle toward the smooth surface
  /// the vertex normals describe (SurfaceHit::terminatorLift), and the sun is judged by
  /// the shading normal alone, so the shadow terminator follows the smooth shading instead
  /// of the facets. false (the default) changes nothing.
  bool smoothTerminator = false;
};

/// A color texture: linear RGB at natural coordinates uv (and world position, for solid
/// textures). Must be thread-safe; the textures module's textures are wrapped into this.
using ColorTexture = std::function<Vec3(Vec2 uv, const Vec3& position)>;

/// The most memory ImplicitOptions::subCells may take per implicit part (256 MB).
inline constexpr size_t kSubCellBudgetBytes = size_t(256) << 20;

/// How a compiled BlobTree becomes exact Embree user geometry.
struct ImplicitOptions {
  /// Edge of the surface cells (one Embree user primitive each), world units; 0 = automatic:
  /// 1.5x the smallest feature radius, clamped to [diagonal/1000, diagonal/40].
  float cellSize = 0.0f;
  /// In a scene with a camera (Scene::setPixelFootprint), the cells (and their pruned
  /// tapes) are no finer than the image needs: edge max(cellSize, kCellPixels x the pixel at
  /// the nearest point of the blob's box) (render::pixelCellSize). The surface is the same
  /// (the tracer is exact in any cell); only the acceleration is coarser. false: cellSize
  /// whatever the camera.
  bool followPixels = true;
  /// Root-finding tolerance (relative to the model's bounds diagonal) and step cap.
  blobtree::TraceOptions trace;
  /// March eight samples at a time with batched field evaluation (the same Lipschitz
  /// guarantee, several times faster); false calls CompiledBlob::intersectCell per cell.
  bool batched = true;
  /// Sub-cells per axis of each surface cell for the batched tracer's bounds
  /// (blobtree::SubCellBounds: an interval and a Lipschitz bound per sub-cell, computed when
  /// a ray first crosses it; a cell uses them from its 256th trace on): a span whose
  /// sub-cells exclude the surface is skipped, and subdivisions use the sub-cells' smaller
  /// Lipschitz bound. The same image, fewer field evaluations. 2..8; 0 or 1 = off (the
  /// cell's own bounds); others throw std::invalid_argument. Reserves 4·k³ bytes per cell
  /// (zero pages until used); when that would pass kSubCellBudgetBytes, k is halved until
  /// it fits (off below 2).
  int subCells = 4;
  /// Prove sub-cells of the surface cells free of the surface (blobtree::FreeSubCells,
  /// batched tracing only): a span crossing only free sub-cells is a miss without field
  /// values. A proof costs about five batches of the tracer, so it is made when the cells
  /// are made only where rays will be many (freeSubCellsEager; the cells free everywhere
  /// are then left out of the scene), elsewhere at a cell's freeSubCellsLazy-th trace. The
  /// same image; false traces every surface cell (the reference).
  bool freeSubCells = true;
  /// Camera samples per surface cell in view (Scene::setExpectedSamples: the image's
  /// samples over the cells whose centres project into it) from which the cells in view are
  /// proved when made. 0: every cell, whatever is expected; without an expectation, none.
  /// 9 lies between the leafy lime at 320x240, 4 spp (7.0; the proofs there save about one
  /// batch each) and the bare poplar at 768x1024, 9 spp (11.4; about seven each).
  float freeSubCellsEager = 9.0f;
  /// A cell not proved when made is proved when this many traces have entered it (1: the
  /// first; wholly free ones stay in the scene, a lookup each). 0: never.
  uint32_t freeSubCellsLazy = 16;
  /// Trace each cell with its pruned tape (blobtree::SurfaceCellOptions::prunedTapes: only
  /// the nodes whose support reaches the cell, identities removed): the same surface, a
  /// shorter walk per batch. false evaluates the whole tape (the reference).
  bool prunedTapes = true;
  /// Raise the scene bounds' lowest y (where the ground goes) from the bisection on field
  /// bounds over slabs of the whole blob, which sums the bounds of primitives that only
  /// meet below the surface (a gap of up to a percent of the diagonal), to the lowest point
  /// found inside the solid on a grid of 8 x 8 x 8 points in each of the lowest surface
  /// cells: the ground then touches a model resting on it (a shell at rest, `render.rest`),
  /// within an eighth of a cell. false keeps the slab bound (every picture before the
  /// option existed).
  bool tightBase = false;
};

/// The textures a part's ids refer to, in id order.
using TextureTable = std::vector<ColorTexture>;

/// The colour of blended attributes a at p from the `count` textures at `textures`:
/// Σ wᵢ·Tᵢ(uv, p) / Σ wᵢ over the attribute's textures at the field-blended uv, or with
/// material.textureLayers over its layers each at its own uv, darkened by the material's
/// ridge; an id past count takes the material's base colour, as do attributes without
/// textures. What exact hits (Scene::attributeColor) and painted meshes show.
Vec3 blendedColor(const blobtree::Attributes& a, const Vec3& p, const Material& material, const ColorTexture* textures,
                  size_t count);

/// Tapered round curves with one material (a plant's internodes in skeleton previews).
struct CurvesPart {
  CurveSet curves;
  Material material;
};

/// Spheres, coloured one by one (fruit), with one material.
struct SpheresPart {
  SphereSet spheres;
  Material material;
};

/// An image laid on a MeshPart by its vertices' uvs and sampled at each hit as an OpenGL
/// texture unit samples it (cpfg's textures):
/// - filter: the magnification or the minification filter, chosen per lookup from GL's
///   texel footprint ρ (texels per pixel: the camera's pixel at the hit, carried onto the
///   triangle along the view ray and through its uv mapping; ρ > 1 minifies). Scenes
///   without a camera (Scene::setPixelFootprint not called) magnify;
/// - alpha test: hits whose alpha is at or below alphaCutoff are cut out (OpenGL's
///   GL_GREATER): camera and shadow rays pass through them;
/// - alpha blending: a hit with alpha between the cutoff and 1 covers that fraction (the
///   renderer composites it over what lies behind; a shadow or sky ray passes it with
///   probability 1 − alpha, decided by a hash of the ray, so the same at any thread count).
struct ImageMap {
  int width = 0;   ///< texels along u (the footprint's scale)
  int height = 0;  ///< texels along v
  /// The surface's linear RGB colour and alpha at uv for a lookup whose pixel covers
  /// texelsPerPixel texels (GL's ρ; 0 without a camera): above 1 the minification filter
  /// applies, and mipmaps take level log2 ρ. Must be thread-safe.
  std::function<Vec4(Vec2 uv, double texelsPerPixel)> sample;
  /// Alpha test threshold; negative: no alpha test and no blending (alpha is ignored).
  float alphaCutoff = -1.0f;
};

/// A triangle mesh. triangleColors, when not empty (one per triangle), replace the
/// material's and the vertices' colours; per-triangle `mesh.materials` are not used here.
/// vertexSurfaces, when not empty (one per vertex), replace the material's (roughness,
/// specular, metallic), interpolated across triangles like vertex colours.
/// image, when set, colours the mesh instead (and may cut it out): the mesh must then have
/// one uv per vertex.
struct MeshPart {
  Mesh mesh;
  Material material;
  std::vector<Vec3> triangleColors;
  TextureTable textures;
  std::shared_ptr<const ImageMap> image;
  std::vector<Vec3> vertexSurfaces;
};

/// A compiled BlobTree ray cast exactly; hit colours blend the table's textures.
/// thinAxes (optional): the axes of the blob's cones as round curves with their radii.
/// When the scene has a pixel footprint (Scene::setPixelFootprint), the segments thinner
/// than the minimum width there are drawn as widened, partly transparent curves (coverage
/// kept, the hair approach) instead of the blob's own sub-pixel surface; otherwise unused.
struct ImplicitPart {
  std::shared_ptr<const blobtree::CompiledBlob> blob;
  Material material;
  ImplicitOptions options;
  TextureTable textures;
  CurveSet thinAxes;
};

/// A polygonized BlobTree: triangles, with vertex colours from its attributes and the table.
/// thinAxes: as ImplicitPart's (sub-pixel twigs the polygonizer cannot resolve).
struct PolygonizedPart {
  std::shared_ptr<const blobtree::PolygonizeResult> mesh;
  Material material;
  TextureTable textures;
  CurveSet thinAxes;
};

/// One part of a Geometry.
using GeometryPart = std::variant<CurvesPart, SpheresPart, MeshPart, ImplicitPart, PolygonizedPart>;

/// Text written over the picture after it is rendered (cpfg's `@L` labels): screen-aligned,
/// unshaded and never hidden by the model (cpfg draws labels with its depth test off), its
/// baseline starting at the pixel where position projects (render/labels.h).
struct TextLabel {
  Vec3 position{0};      ///< world units
  std::string text;
  Vec3 color{0.0f};      ///< the colour the image file shows (sRGB values in [0, 1])
  std::string fontFile;  ///< a TrueType font file
  int sizePixels = 16;   ///< the font's size (its em), pixels
};

/// What a model builds for one stage: its parts, added to a scene in order, and its labels.
struct Geometry {
  std::vector<GeometryPart> parts;
  std::vector<TextLabel> labels;
};

}  // namespace sprig::render
