#pragma once
/// Pinhole camera and automatic framing of a model from its bounds.
///
/// World space is Y up. A camera is a position, a target, an up vector and a vertical
/// field of view; film coordinates are pixels with (0,0) at the top-left corner. Framing
/// depends only on the box, the view and the aspect ratio, so every stage of a growth
/// sequence framed with the final stage's box shares one camera.

#include <string>

#include "core/types.h"

namespace sprig::render {

/// A ray: origin and unit direction.
struct Ray {
  Vec3 origin{0};            ///< world position
  Vec3 direction{0, 0, -1};  ///< unit direction
};

/// A camera's orthonormal frame: film x, film y and the view direction.
struct CameraBasis {
  Vec3 right, up, forward;
};

/// The camera's pixel carried into the world: how fine a model seen through it needs its
/// acceleration (surface cells, pruned tapes, the mesh mode's polygonization cell) to be.
/// A frame's cost then follows its pixels, not the model's finest feature.
struct PixelScale {
  Vec3 eye{0};                 ///< camera position
  Vec3 forward{0, 0, -1};      ///< unit view direction
  float pixelPerDepth = 0.0f;  ///< world size of one pixel at unit depth along forward
  /// World size of one pixel at the point of box nearest the camera along its view (the
  /// smallest pixel anywhere on the box: the finest the model inside can appear); 0 when
  /// box is empty or reaches the plane through the eye across the view.
  float nearestPixel(const Box3& box) const;
};

/// Pixels per acceleration cell (pixelCellSize): a cell at least two pixels wide where the
/// model comes nearest. Two because thin parts narrower than two pixels are drawn as
/// widened curves anyway (Scene::setPixelFootprint, RenderSettings::thinMinPixels), so a
/// polygonization cell of two pixels loses nothing the image shows as a surface.
constexpr float kCellPixels = 2.0f;

/// The edge (world units) of the acceleration cells of a model whose support box is box,
/// seen through pixels, when the model itself asks for ownCell (its species' cell, or the
/// automatic cell from its finest feature):
///   max(ownCell, cellPixels · pixels.nearestPixel(box)).
/// Never finer than ownCell; ownCell itself when the rule does not bind (large images, a
/// camera inside the box) or ownCell <= 0 (nothing to build).
float pixelCellSize(float ownCell, const PixelScale& pixels, const Box3& box, float cellPixels = kCellPixels);

/// The primary rays of one camera and image size, with the camera's frame and the film's
/// extent computed once (Camera::generateRay computes them per call).
struct FilmRays {
  Vec3 position{0};
  CameraBasis basis;
  float tanX = 1, tanY = 1, width = 1, height = 1;
  /// Primary ray through film point (px, py) in pixels (y down): the same bits as
  /// Camera::generateRay.
  Ray ray(float px, float py) const {
    const float sx = (2.0f * px / width - 1.0f) * tanX;
    const float sy = (1.0f - 2.0f * py / height) * tanY;
    return {position, glm::normalize(basis.forward + sx * basis.right + sy * basis.up)};
  }
};

/// Pinhole camera looking from `position` toward `target`.
struct Camera {
  Vec3 position{0, 0, 5};  ///< eye, world units
  Vec3 target{0};          ///< point at the image center
  Vec3 up{0, 1, 0};        ///< approximate up; the camera is rolled so it projects vertical
  float fovYDeg = 35.0f;  ///< vertical field of view, degrees

  /// Primary ray through film point (px, py) in pixels of a width x height image (y down).
  Ray generateRay(float px, float py, int width, int height) const;
  /// The primary rays of a width x height image (for many rays: generateRay's per-ray set-up once).
  FilmRays filmRays(int width, int height) const;
  /// Projects a world point to film pixels; returns false when it lies behind the camera.
  bool project(const Vec3& p, int width, int height, Vec2& film) const;
  /// The frame generateRay and project use (up rolled to be perpendicular to the view).
  CameraBasis basis() const;
  /// World size of one pixel of a height-pixel image at unit depth along the view.
  float pixelPerDepth(int height) const;
  /// The camera's pixel in a height-pixel image, for pixelCellSize.
  PixelScale pixelScale(int height) const;
};

/// Largest coordinate (absolute, world units) a camera or a framed box may have: Embree
/// traces rays whose origins lie within about 1.8e18 and whose directions are finite; 1e15
/// leaves room for the camera's distance from the box.
inline constexpr float kMaxRenderCoordinate = 1e15f;

/// Why camera cannot make valid rays (a position or target that is not finite or lies beyond
/// kMaxRenderCoordinate, a target at the position, a field of view outside (0, 180)
/// degrees), or an empty string when it can.
std::string cameraProblem(const Camera& camera);

/// True when every coordinate of box is finite and within kMaxRenderCoordinate (an empty
/// box, which frames the unit cube, counts as inside).
bool boxInRenderRange(const Box3& box);

/// A viewing direction for automatic framing.
struct ViewSpec {
  double azimuthDeg = 30.0;    ///< around +Y, measured from +Z toward +X (0 = camera on +Z looking at -Z)
  double elevationDeg = 15.0;  ///< above the horizontal plane
  double fovYDeg = 35.0;       ///< vertical field of view
  double margin = 0.06;        ///< fraction of the half-frame left free on each side, in [0, 0.9]
};

/// Unit vector from a target toward a viewer at (azimuth, elevation), Y up.
Vec3 directionFromAngles(double azimuthDeg, double elevationDeg);

/// Camera at (azimuth, elevation, distance) from target, looking at it.
Camera orbitCamera(const Vec3& target, double azimuthDeg, double elevationDeg, double distance, double fovYDeg);

/// Camera looking along the view direction that tightly fits the eight corners of box in
/// a width/height = aspect frame, leaving `margin` free on every side. The camera is panned
/// (not turned) to center the projected box. An empty box frames the unit cube; a box too
/// small for single precision at its position (a point) is framed as a box of the smallest
/// size that is not (1e-5 of its largest coordinate, at least 1e-15), so the camera never
/// stands on its target. Throws std::invalid_argument for a box outside boxInRenderRange.
Camera frameBounds(const Box3& box, const ViewSpec& view, double aspect);

}  // namespace sprig::render
