#pragma once
/// Helpers the kinds use to hand `sprig mesh` their parts (KindModel::exportParts):
/// polygonized BlobTrees coloured as the renderer colours them, and meshes split by their
/// per-triangle ids.

#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "blobtree/polygonize.h"
#include "core/mesh.h"
#include "core/mesh_clean.h"
#include "core/mesh_io.h"
#include "organisms/simplify.h"
#include "model/species.h"
#include "render/geometry.h"

namespace sprig {

/// Texture id meaning "no texture contributes" in paintPolygonized's triangle ids.
inline constexpr uint32_t kNoPartTexture = 0xffffffffu;

/// The polygonizer's options a species' look asks for (render.mesher), with the vertices'
/// blended attributes (VertexData::Blend) for painting.
blobtree::PolygonizeOptions polygonizeOptions(const SpeciesRender& look);

/// The cell at which a probe polygonizes, in units of the automatic cell (lodCellSize).
inline constexpr float kLodProbeCells = 4.0f;

/// The cell edge at which blob's surface polygonizes into about `triangles` triangles, for
/// levels of detail that simplify the full mesh away anyway (`sprig mesh --lod` without
/// --cell). A polygonized surface has about area / h² triangles at cell h (the mesher's
/// constant aside), so one probe at h_p = kLodProbeCells times the automatic cell h_a
/// (resolveCellSize of options), that only finds the cells and meshes the signs (no root
/// search, normals or attributes: about 1/16 of the automatic cell's cells and none of its
/// vertex work), counts T_p triangles, and the cell is h_p·sqrt(T_p / triangles) clamped
/// to [h_a, lodCellCeiling]: h_a when the automatic cell gives no more than `triangles`, or
/// when the ceiling is h_a (then no probe is made). Twigs thinner than the probe's cells
/// vanish from the probe, so the count errs low and the cell coarse: callers ask for a
/// margin over what they need (kLodCellMargin). Returns options.cellSize when that is set.
/// Deterministic (the polygonizer is).
float lodCellSize(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options, size_t triangles,
                  bool keepLimbs = true);

/// The coarsest cell lodCellSize takes, given the automatic cell `fine`: the probe's cell,
/// but where the automatic cell keeps every limb in one piece (fine <= limbFraction ·
/// thinnestLimb(), blobtree/cell_size.h) never coarser than that edge, so that the promise
/// holds at the coarser cell too (ABOP Fig. 2.8, whose automatic cell is its limb edge,
/// lost the finest twigs of its crown at 1.7 times it). Where the automatic cell already
/// cuts the thinnest limbs (the lime's, below the limb term's cost bound) there is no
/// promise to keep, and more of those twigs' tips fall apart at the coarser cell.
/// keepLimbs false (a tree in leaf, whose crown hides its twigs: the lime's LOD0 renders
/// the same either way): the probe's cell.
float lodCellCeiling(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options, float fine,
                     bool keepLimbs = true);

/// The polygonized mesh of result with, per vertex, the colour the renderer gives it
/// (Σ wᵢ·textureᵢ(uv, p) / Σ wᵢ over the vertex's textures; base where none contributes,
/// as render::Scene::attributeColor), and per triangle (Mesh::materials) the texture id
/// with the largest weight summed over its three vertices (kNoPartTexture when none).
/// result must carry attributes (PolygonizeOptions::VertexData::Blend; throws
/// std::invalid_argument otherwise). O(V·textures).
Mesh paintPolygonized(const blobtree::PolygonizeResult& result, const render::TextureTable& textures, const Vec3& base);
/// paintPolygonized with a material: its base colour, and its textureLayers and
/// ridge darkening applied as render::Scene::attributeColor applies them (the ridge's
/// relief is shading, not colour: not baked).
Mesh paintPolygonized(const blobtree::PolygonizeResult& result, const render::TextureTable& textures,
                      const render::Material& material);

/// Size of the images exports bake textures into: kExportTextureLong texels along the
/// texture's long axis (a tree's height, a shell's spiral), kExportTextureShort around a
/// branch, kExportTextureAround around a shell's generating curve. Powers of two.
inline constexpr int kExportTextureLong = 2048;
inline constexpr int kExportTextureShort = 512;
inline constexpr int kExportTextureAround = 1024;

/// A width x height texture whose texel centred at texture coordinate (s, t) (t = 0 at the
/// bottom row, as Mesh::uvs) has colour colorAt(s, t); texels are computed in parallel
/// (colorAt must be thread-safe). O(width·height) calls.
std::shared_ptr<PartTexture> bakeTexture(int width, int height, const std::function<Vec3(double s, double t)>& colorAt,
                                         const UvSeamOptions& seams);

/// Texture budget of an atlas (bakeAtlas): every triangle gets its own square patch of
/// kAtlasMaxCell x kAtlasMaxCell texels, smaller when the triangles would not fit an image
/// of kAtlasMaxSize x kAtlasMaxSize, down to kAtlasMinCell; a part with more triangles than
/// (kAtlasMaxSize / kAtlasMinCell)² = 1,048,576 gets no atlas (it keeps its vertex colours).
inline constexpr int kAtlasMaxSize = 4096;
inline constexpr int kAtlasMaxCell = 16;
inline constexpr int kAtlasMinCell = 4;

/// The patch size and grid of an atlas for a number of triangles: cell texels per side,
/// columns x rows patches; cell is 0 when the triangles exceed the budget (or are none).
struct AtlasLayout {
  int cell = 0, columns = 0, rows = 0;
  int width() const { return cell * columns; }
  int height() const { return cell * rows; }
};
AtlasLayout atlasLayout(size_t triangles);

/// Colour of triangle `triangle` of a mesh at the point with barycentric coordinates bary
/// (point = Σ baryₖ·positionₖ, given too). Called in parallel: must be thread-safe.
using SurfaceColor = std::function<Vec3(size_t triangle, const Vec3& point, const Vec3& bary)>;

/// Bakes mesh's colours into an atlas (PartTexture::atlas): triangle i owns the cell-sized
/// square patch i of atlasLayout (row-major from the image's bottom-left); its corners sit
/// on the centres of the texels one inside the patch, at (1.5, 1.5), (cell − 1.5, 1.5) and
/// (1.5, cell − 1.5) texels from the patch's corner, so a lookup at a corner reads the
/// colour there alone and a bilinear lookup anywhere in the triangle reads only its own patch.
/// Every texel of the patch is colorAt at the barycentric point of its centre, clamped to
/// the triangle (the texels outside the triangle are its gutter). Null when the mesh has
/// no triangles or more than the budget. O(triangles · cell²) colorAt calls, in parallel;
/// the result does not depend on the thread count.
std::shared_ptr<PartTexture> bakeAtlas(const Mesh& mesh, const SurfaceColor& colorAt);

/// The most images bakeAtlases makes at once.
inline constexpr int kMaxAtlases = 4;
/// The values of one texel of atlases baked together: out[k] is image k's value at the
/// barycentric point of triangle `triangle` (as SurfaceColor). Called in parallel.
using SurfaceTexel = std::function<void(size_t triangle, const Vec3& point, const Vec3& bary, Vec3* out)>;
/// bakeAtlas of count images (1..kMaxAtlases) in the same layout at once, each texel's
/// values computed by one texelAt call (a normal map and a colour map from one ray cast).
/// gutterCopies: texelAt is called only for the texels whose centres lie in the triangle
/// (105 of the 256 texels of a 16-texel patch); each gutter texel copies the inside texel nearest to its
/// clamped point. eightBit: empty, float images (PartTexture::image); else count
/// encodings, image k stored 8-bit in eightBit[k] (PartTexture::image8: the bytes its PNG
/// holds, those writeImage gives the float image; 3 bytes a texel instead of 16). Empty
/// when bakeAtlas would give null or count (or eightBit's size) is out of range.
/// Thread-count independent.
std::vector<std::shared_ptr<PartTexture>> bakeAtlases(const Mesh& mesh, int count, const SurfaceTexel& texelAt,
                                                      bool gutterCopies = false,
                                                      const std::vector<ImageEncoding>& eightBit = {});
/// bakeAtlas with the image deferred (PartTexture::deferred): the corners now, the texels
/// (the same bytes) when a writer first reads PartTexture::pixels(); never when no written
/// file uses the texture (a level of detail replaces the full part's atlas). mesh and
/// colorAt are kept until then. Null as bakeAtlas. O(triangles) now.
std::shared_ptr<PartTexture> deferAtlas(std::shared_ptr<const Mesh> mesh, SurfaceColor colorAt);

/// The colour the renderer gives blended BlobTree attributes at p (as
/// render::Scene::attributeColor: Σ wᵢ·textureᵢ / Σ wᵢ, per layer with
/// material.textureLayers, times the contact darkening; base colour where none contributes).
Vec3 paintedColor(const blobtree::Attributes& a, const Vec3& p, const render::TextureTable& textures,
                  const render::Material& material);

/// The renderer's colour of a BlobTree's surface near p: p moved onto F = 0.5 by up to
/// three Newton steps along ∇F (stopping before a step that would leave p by more than
/// maxMove, e.g. the triangle's longest edge, and once a step would be shorter than
/// maxMove/1000), the attributes sampled there and coloured by paintedColor. One
/// CompiledBlob::sample per step.
Vec3 blobSurfaceColor(const blobtree::CompiledBlob& blob, const Vec3& p, float maxMove, const render::TextureTable& textures,
                      const render::Material& material);

/// Gives a polygonized BlobTree part an atlas of its colours (blobSurfaceColor at every
/// texel's surface point, on the part's surface as it is at this call), when the part's
/// vertex colours are not all its base colour and it has no texture yet. The atlas's image
/// is deferred (deferAtlas: baked when first written; blob, textures and material are kept
/// until then). Returns the texture's triangles' patch size (0 when there is no atlas:
/// constant colour, already textured, or above the budget).
int atlasBlobPart(ExportPart& part, std::shared_ptr<const blobtree::CompiledBlob> blob, render::TextureTable textures,
                  render::Material material);

/// Bakes a part's vertex colours, interpolated over each triangle as the renderer
/// interpolates a mesh's vertex colours, into an atlas (when they are not all the base
/// colour and the part has no texture). Returns the patch size as atlasBlobPart.
int atlasVertexColors(ExportPart& part);

/// Sets each vertex's uv of result's mesh to its heaviest contributing primitive's own uv
/// (Attributes::layers[0]) where it has layers: the coordinates in which a layered material
/// (render::Material::textureLayers, a tree's bark) colours the vertex, where the field-blended
/// uv mixes the angles of different axes (swirls round a junction or a scar). O(V).
void useHeaviestLayerUvs(blobtree::PolygonizeResult& result);

/// Maps a bark texture onto a tree's wood: the mesh's uvs are the bark's (u, v) (u turns
/// around the branch, v along it: useHeaviestLayerUvs, each vertex in its own cone's); v is rescaled to
/// t = (v − vMin)/(vMax − vMin) over the mesh's range and the image covers one period of u
/// (repeating, the bark closes at u = 1) times that range, each texel bark((s, v(t))).
/// Sets part.material.texture. Throws std::invalid_argument when the mesh has no uvs.
void textureBark(ExportPart& part, const std::function<Vec3(Vec2 uv)>& bark);

/// What finishExportParts did.
struct ExportFinish {
  Vec3 offset{0.0f};            ///< added to every position
  std::vector<DegenerateReport> removed;  ///< degenerate triangles removed, per part
};

/// The last steps before `sprig mesh` writes parts: removes every part's degenerate
/// triangles (removeDegenerateTriangles; an atlas keeps the corners of the others), then
/// moves every part by one offset so that the box of the parts that have triangles has its
/// lowest y at 0 and its centre at x = z = 0 (the model stands on the ground plane of a
/// Y-up viewer at the origin). Textures and normals are unchanged. O(T + V).
ExportFinish finishExportParts(std::vector<ExportPart>& parts);

/// The offset that stands parts on the ground as finishExportParts does: the box of the
/// parts that have triangles gets its lowest y at 0 and its centre at x = z = 0 (zero when
/// no part has triangles). O(V).
Vec3 groundOffset(const std::vector<ExportPart>& parts);
/// Adds offset to every position of parts. O(V).
void moveParts(std::vector<ExportPart>& parts, const Vec3& offset);

/// The triangles of mesh grouped by their Mesh::materials id, in increasing id order;
/// each group is its own mesh (only the vertices it uses, in their original order; every
/// per-vertex array kept; materials cleared). mesh.materials must have one id per triangle.
std::vector<std::pair<uint32_t, Mesh>> splitByMaterial(const Mesh& mesh);

/// polygonizeDetailed(blob, options), simplified to look.simplify of the surface's extent
/// when that is above 0 (the per-vertex attributes follow the vertices that remain): the
/// surface of a mesh-mode render. With look.pixels (a render's camera) the cell is
/// render::pixelCellSize of the blob's own (options.cellSize or the automatic cell): no
/// finer than the image needs.
blobtree::PolygonizeResult polygonizeForLook(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options,
                                             const SpeciesRender& look);

/// Simplifies every part of a model to a geometric error (organisms::simplifyToError):
/// relativeError is a fraction of the whole model's extent (the largest side of the
/// bounding box of all parts), so every part gets the same error in model units.
/// Normals, texture coordinates and colours stay at the vertices that remain; a closed,
/// manifold part stays so. A part textured by an atlas (one patch per triangle) loses the
/// atlas, since its triangles change, and keeps its vertex colours (the renderer's colours
/// at the vertices that remain); its name is appended to droppedAtlases when given.
/// Returns one report per part, in order. O(T log T).
std::vector<organisms::SimplifyReport> simplifyParts(std::vector<ExportPart>& parts, double relativeError,
                                                     std::vector<std::string>* droppedAtlases = nullptr);

}  // namespace sprig
