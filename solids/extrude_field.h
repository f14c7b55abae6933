#pragma once
/// A 2-D region extruded into a slab (Cutler et al. §5.2, the paper's `2D_EXTRUDE`): the
/// roots of the urban tree drawn as a sketch and given depth.
///
/// The region is the set of pixels of a mask image marked inside. Its exact 2-D signed
/// distance is computed once, at pixel resolution, with the linear-time Euclidean distance
/// transform of Felzenszwalb and Huttenlocher, "Distance transforms of sampled functions"
/// (Theory of Computing 8, 2012), run twice: to the nearest inside pixel centre (for
/// outside pixels) and to the nearest outside pixel centre (for inside pixels), each less
/// half a pixel, so the zero set lies between the centres. Samples interpolate it
/// bilinearly. The transform runs over the image padded by half its larger side on every
/// edge (padding pixels are outside), so the distance keeps growing correctly beyond the
/// image; beyond the padding a point takes the value at the nearest padded point plus its
/// distance to it (an upper bound, exact along the padding's normals).
///
/// In 3-D the image lies on the plane perpendicular to the axis; the 2-D distance d2 and
/// the slab distance dh = |h - mid| - half combine as a box's do:
/// d = length(max((d2, dh), 0)) + min(max(d2, dh), 0), exact outside the slab's corner too.

#include <string>
#include <utility>
#include <vector>

#include "core/types.h"
#include "solids/distance_field.h"

namespace sprig::solids {

/// A mask on a grid of width x height pixels, row-major from the top row.
struct Mask2d {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> inside;  ///< 1 = in the region, one per pixel
};

/// Where the mask lies and how deep it is extruded.
struct ExtrudeOptions {
  /// World size of the whole image along its columns (u) and rows (v).
  glm::dvec2 size{1.0, 1.0};
  /// Centre of the image in plane coordinates (u, v) (default axis y: u = x, v = z).
  glm::dvec2 center{0.0, 0.0};
  /// Extrusion axis (unit). The image plane's u, v directions are the x and z axes turned
  /// by the smallest rotation taking +y to axis: for axis y, columns run along +x and rows
  /// along +z, the image's top row at the -z edge.
  DVec3 axis{0.0, 1.0, 0.0};
  /// The slab lo <= dot(p, axis) <= hi, world units.
  double heightLo = 0.0, heightHi = 1.0;
};

/// The image plane's column (u) and row (v) directions for a unit extrusion axis: the x and
/// z axes turned by the smallest rotation taking +y to axis (ExtrudeOptions::axis).
std::pair<DVec3, DVec3> imagePlaneAxes(const DVec3& axis);

/// Smallest and largest side of a mask pixel (world units): the transform squares distances
/// of up to a few thousand pixels and divides by the pixel side, in double precision, and
/// keeps the distances as floats; within these bounds every step stays finite.
inline constexpr double kMinExtrudePixel = 1e-12;
inline constexpr double kMaxExtrudePixel = 1e12;

/// Why options.size cannot be laid over a width x height mask (a pixel side, size over
/// pixels, outside [kMinExtrudePixel, kMaxExtrudePixel]; NaN is outside too), or "".
std::string extrudeScaleProblem(int width, int height, const ExtrudeOptions& options);

/// 2-D signed distances of mask, in pixels of unit spacing scaled by (pixelU, pixelV)
/// world units: negative inside. Returned row-major like the mask, over the mask padded
/// by `pad` pixels on every side ((width + 2 pad) x (height + 2 pad) values).
/// Felzenszwalb-Huttenlocher exact EDT, O(pixels). Throws std::invalid_argument for a pixel
/// side outside [kMinExtrudePixel, kMaxExtrudePixel].
std::vector<float> signedDistance2d(const Mask2d& mask, double pixelU, double pixelV, int pad);

/// The mask extruded along options.axis between the two heights. An empty mask (no inside
/// pixel) gives a field positive everywhere. Throws std::invalid_argument for a mask of no
/// pixels, a non-positive size, pixels extrudeScaleProblem refuses or heightHi <= heightLo.
/// Cost: construction O(pixels); each sample O(1).
FieldPtr extrudeField(const Mask2d& mask, const ExtrudeOptions& options);

}  // namespace sprig::solids
