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
#include "core/mesh_io.h"
#include "organisms/simplify.h"
#include "model/species.h"
#include "render/geometry.h"

namespace sprig {

/// Texture id meaning "no texture contributes" in paintPolygonized's triangle ids.
inline constexpr uint32_t kNoPartTexture = 0xffffffffu;

/// The polygonized mesh of result with, per vertex, the colour the renderer gives it
/// (Σ wᵢ·textureᵢ(uv, p) / Σ wᵢ over the vertex's textures; base where none contributes,
/// as render::Scene::attributeColor), and per triangle (Mesh::materials) the texture id
/// with the largest weight summed over its three vertices (kNoPartTexture when none).
/// result must carry attributes (PolygonizeOptions::attributes). O(V·textures).
/// The polygonizer's options a species' look asks for (render.mesher).
blobtree::PolygonizeOptions polygonizeOptions(const SpeciesRender& look);

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

/// Maps a bark texture onto a tree's wood: the mesh's uvs are the bark's (u, v) (u turns
/// around the branch, v along it, as the polygonizer blends them); v is rescaled to
/// t = (v − vMin)/(vMax − vMin) over the mesh's range and the image covers one period of u
/// (repeating, the bark closes at u = 1) times that range, each texel bark((s, v(t))).
/// Sets part.material.texture. Throws std::invalid_argument when the mesh has no uvs.
void textureBark(ExportPart& part, const std::function<Vec3(Vec2 uv)>& bark);

/// The triangles of mesh grouped by their Mesh::materials id, in increasing id order;
/// each group is its own mesh (only the vertices it uses, in their original order; every
/// per-vertex array kept; materials cleared). mesh.materials must have one id per triangle.
std::vector<std::pair<uint32_t, Mesh>> splitByMaterial(const Mesh& mesh);

/// polygonizeDetailed(blob, options), simplified to look.simplify of the surface's extent
/// when that is above 0 (the per-vertex attributes follow the vertices that remain): the
/// surface of a mesh-mode render.
blobtree::PolygonizeResult polygonizeForLook(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options,
                                             const SpeciesRender& look);

/// Simplifies every part of a model to a geometric error (organisms::simplifyToError):
/// relativeError is a fraction of the whole model's extent (the largest side of the
/// bounding box of all parts), so every part gets the same error in model units.
/// Normals, texture coordinates and colours stay at the vertices that remain; a closed,
/// manifold part stays so. Returns one report per part, in order. O(T log T).
std::vector<organisms::SimplifyReport> simplifyParts(std::vector<ExportPart>& parts, double relativeError);

}  // namespace sprig
