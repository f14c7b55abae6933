#pragma once
/// Private: the state behind render::Scene, shared by scene.cpp and implicit.cpp.

#include <embree3/rtcore.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "blobtree/compiled.h"
#include "render/scene.h"

namespace sprig::render::detail {

/// A compiled blob with its surface cells, the payload of one Embree user geometry.
/// Defined in implicit.cpp only: other files hold it through a shared_ptr.
struct ImplicitData;

/// Curve vertices as drawn (widened to the pixel footprint) and as they are, for the
/// opacity of a hit; the payload of a curve geometry's occlusion filter.
struct CurveData {
  std::vector<Vec4> drawn;      ///< xyz, radius as given to Embree
  std::vector<Vec4> real;       ///< xyz, true radius
  std::vector<uint32_t> segments;
  bool widened = false;         ///< some radius was raised (opacity may be below 1)
  bool standIn = false;         ///< thin axes standing for an implicit or mesh part
  /// Opacity at parameter u of segment prim: true radius / drawn radius.
  float opacity(uint32_t prim, float u) const {
    if (!widened) return 1.0f;
    const uint32_t i = segments[prim];
    const float r = (1.0f - u) * real[i].w + u * real[i + 1].w;
    const float d = (1.0f - u) * drawn[i].w + u * drawn[i + 1].w;
    return d > 0.0f ? std::min(1.0f, r / d) : 1.0f;
  }
};

/// The camera's pixel: its basis and its world size per unit depth (square pixels).
struct PixelView {
  Vec3 eye{0};
  Vec3 forward{0, 0, -1};  ///< unit view direction
  Vec3 right{1, 0, 0};     ///< unit film x
  Vec3 up{0, 1, 0};        ///< unit film y
  float pixelPerDepth = 0.0f;
};

/// The camera samples a scene expects (Scene::setExpectedSamples).
struct ExpectedSamples {
  PixelView view;
  int width = 0, height = 0;  ///< the image, pixels
  int spp = 0;                ///< camera samples per pixel
};

/// A triangle geometry coloured by an ImageMap: its triangles and uvs, for the hit colour
/// and the payload of its alpha filter functions.
struct ImageMapData {
  std::shared_ptr<const ImageMap> map;
  std::vector<Vec3> positions;
  std::vector<glm::uvec3> triangles;
  std::vector<Vec2> uvs;
  std::optional<PixelView> view;  ///< the camera, when the scene has one
  /// GL's texel footprint ρ (texels per pixel) at barycentric (u, v) of triangle prim: the
  /// camera's two pixel steps at the hit, carried along the view ray onto the triangle's
  /// plane, through its uv mapping, scaled by the image size; the larger of the two
  /// lengths. 0 without a camera, for a degenerate triangle or a point behind the camera;
  /// infinite where the view ray grazes the plane.
  double texelsPerPixel(uint32_t prim, float u, float v) const;
  /// The map's colour and alpha at barycentric (u, v) of triangle prim: its interpolated uv
  /// at this hit's texelsPerPixel.
  Vec4 sample(uint32_t prim, float u, float v) const;
};

/// What the renderer needs to know about one Embree geometry to shade its hits.
struct GeometryRecord {
  enum class Kind { Curves, Triangles, Spheres, Implicit } kind = Kind::Triangles;
  uint32_t material = 0;
  std::vector<Vec3> positions;               ///< triangles
  std::vector<glm::uvec3> triangles;         ///< triangles
  std::vector<Vec3> normals;                 ///< optional per-vertex normals (triangles)
  std::vector<Vec3> vertexColors;            ///< optional per-vertex colors (triangles)
  std::vector<Vec3> vertexSurfaces;          ///< optional per-vertex (roughness, specular, metallic)
  std::vector<Vec2> uvs;                     ///< optional per-vertex uvs (triangles, textured material)
  std::vector<Vec3> primitiveColors;         ///< optional per-primitive colors (any kind)
  std::vector<uint32_t> primitiveMaterials;  ///< optional per-primitive material ids
  std::shared_ptr<const ImplicitData> implicit;  ///< Implicit
  std::shared_ptr<const CurveData> curves;       ///< Curves
  std::shared_ptr<const ImageMapData> image;     ///< Triangles coloured by an image map
  uint32_t textureBase = 0;                      ///< the part's texture table in Scene::Impl::textures
  uint32_t textureCount = Scene::kAllTextures;   ///< its size (kAllTextures: the scene's whole table)
};

/// Embree intersect context extended with the last implicit hit (its normal and blended
/// attributes), so the user-geometry callback hands them to Scene::intersect.
struct HitContext {
  RTCIntersectContext base;  ///< must stay first: Embree passes &base to callbacks
  blobtree::Hit implicitHit;
};

}  // namespace sprig::render::detail

namespace sprig::render {

struct Scene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::string error;
  std::vector<Material> materials;
  std::vector<ColorTexture> textures;
  std::vector<detail::GeometryRecord> records;
  Box3 bounds;
  std::vector<TextLabel> labels;  ///< Scene::labels
  SceneStats stats;
  bool committed = false;
  bool prunedTapes = Scene::prunedTapesDefault();  ///< setPrunedTapes
  bool anyGeometry = false;               ///< something was added (the footprint is fixed then)
  std::optional<PixelFootprint> footprint;  ///< minimum width of thin curves, when set
  std::optional<detail::PixelView> view;    ///< the camera's pixel, when set (image maps)
  /// setCellFootprint's camera: implicit models' cells follow its pixel instead of view's.
  std::optional<detail::PixelView> cellView;
  std::optional<detail::ExpectedSamples> expected;  ///< setExpectedSamples
  /// Something added was shaped by the footprint or the view beyond an implicit model's
  /// cell size (curves, thin axes, image maps): no other camera is served (Scene::servesCamera).
  bool followsCamera = false;
  /// An implicit model whose cell size followed the camera's pixel (Scene::servesCamera).
  struct FollowedCell {
    float ownCell = 0;  ///< the cell it asked for
    float usedCell = 0;  ///< the cell the camera gave it
    Box3 support;
  };
  std::vector<FollowedCell> followedCells;

  /// Commits geometry, attaches it under the next id and records how to shade it.
  uint32_t attach(RTCGeometry geometry, detail::GeometryRecord record);
  /// Appends a part's texture table; returns the scene id of its texture 0.
  uint32_t addTextureTable(const TextureTable& table);
  /// Fills geometry's vertex buffer with balls (xyz centre, w radius: curve vertices or
  /// spheres) and grows the scene bounds by each ball.
  void setBallVertices(RTCGeometry geometry, const std::vector<Vec4>& balls);
  /// Adds curves (widened to the footprint when there is one) as Embree round linear curves.
  uint32_t addCurveGeometry(std::shared_ptr<detail::CurveData> data, uint32_t material);
  /// Adds record's triangles as Embree triangle geometry (with alpha filter functions when
  /// record.image cuts out).
  uint32_t addTriangles(detail::GeometryRecord record);
};

}  // namespace sprig::render
