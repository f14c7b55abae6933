#pragma once
/// Maps baked from a part's full-resolution surface onto a simplified level of it
/// (`sprig mesh`'s levels of detail, docs/MESHES.md "Levels of detail"): a tangent-space
/// normal map carrying the relief the level lost (PCM ridges, scars, bark furrows, a shell's
/// cords), and the colours of the full mesh at the same points.
///
/// For every texel of a level's atlas (one patch per triangle, bakeAtlas's layout) the
/// point on the low triangle and its interpolated normal cast a ray each way along that
/// normal against the full mesh (an Embree scene through render::Scene), within a distance
/// bound; the nearest hit whose shading normal faces the same side gives the texel its
/// normal, expressed in the texel's tangent frame, and its colour.

#include <memory>
#include <optional>

#include "core/mesh.h"
#include "core/mesh_io.h"
#include "render/scene.h"

namespace sprig {

/// The full-resolution mesh of one part in an Embree scene (positions, normals and vertex
/// colours; per-triangle ids and uvs are not used). Immutable once built: nearest() may be
/// called from any number of threads. Cost: a BVH build over the mesh's triangles.
class DetailSurface {
 public:
  /// Builds the scene of full; baseColor is the colour of a hit where full has no vertex
  /// colours. colors false: the scene keeps no vertex colours (every hit has baseColor), for
  /// a bake that reads only normals. Throws std::runtime_error on an Embree error.
  DetailSurface(const Mesh& full, const Vec3& baseColor, bool colors = true);

  /// The nearest of the hits of the rays p + s·normal and p − s·normal, s in
  /// [0, maxDistance], whose shading normal has a positive dot product with normal (hits of
  /// the far side of a thin branch are skipped); nothing when neither ray gives one.
  /// normal must be unit.
  std::optional<render::SurfaceHit> nearest(const Vec3& p, const Vec3& normal, float maxDistance) const;

  /// Triangles of the full mesh.
  size_t triangles() const { return triangles_; }

 private:
  render::Scene scene_;
  size_t triangles_ = 0;
};

/// The value of a tangent-space normal n (unit, components in [−1, 1]) in a normal map:
/// (128 + round(127·nᵢ))/255 per channel, so that an 8-bit file holds the byte
/// 128 + round(127·nᵢ) exactly and the flat normal (0, 0, 1) is (128, 128, 255); glTF's
/// decoding 2·v − 1 gives nᵢ within 1/127.
Vec3 encodeTangentNormal(const Vec3& n);

/// What bakeDetailMaps made.
struct DetailMaps {
  std::shared_ptr<PartTexture> normal;  ///< the normal map (null when the part has no atlas layout)
  std::shared_ptr<PartTexture> color;   ///< the full mesh's colours (when asked for and it has colours)
  size_t texels = 0;  ///< texels baked
  size_t hits = 0;    ///< of them, with a hit of the full mesh (the rest: flat normal, the level's colour)
};

/// Bakes low's maps from full in bakeAtlas's layout of low's triangles. Each texel of
/// triangle t: N = the interpolated corner normal (splitCreaseNormals of low: the normals
/// the glTF writer writes), T = the interpolated cornerTangent of the atlas' uv mapping
/// made perpendicular to N, B = cross(N, T)·w; the nearest hit within maxDistance
/// (DetailSurface::nearest) gives the normal map (h·T, h·B, h·N) of its shading normal h,
/// encoded by encodeTangentNormal, and the colour map the full mesh's interpolated vertex
/// colour; a miss gives (0, 0, 1) and low's own interpolated colour (its base colour
/// without vertex colours). colors false: no colour map. Both images are 8-bit
/// (PartTexture::image8: the normal map in the Data encoding, the colours in TextureMap's
/// sRGB bytes), as the writers store them. low must have normals. Cost:
/// two rays per texel, in parallel over triangles; the same bytes at any thread count.
DetailMaps bakeDetailMaps(const Mesh& low, const Vec3& baseColor, const DetailSurface& full, float maxDistance, bool colors);

}  // namespace sprig
