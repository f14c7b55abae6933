#pragma once
/// Private: small geometric helpers of bounds and warps: perpendicular frames, boxes of
/// cylinders and of transformed boxes, axial extents, spectral norms, unbounded boxes.

#include "core/types.h"

namespace sprig::blobtree::detail {

/// A unit vector perpendicular to axis (unit), from preferred when possible.
Vec3 perpendicular(Vec3 axis, Vec3 preferred);
/// World box of a cylinder around axis (origin, axis) with axial range [h0, h1] and radius r.
Box3 cylinderBox(Vec3 origin, Vec3 axis, float h0, float h1, float r);
/// Axial range and max radial distance of a box's corners about an axis.
void axialExtent(const Box3& box, Vec3 origin, Vec3 axis, float& h0, float& h1, float& rmax);
/// Bounding box of the 8 corners of box mapped by an affine matrix.
Box3 transformBox(const Mat4& m, const Box3& box);
/// Spectral norm bound of a 3x3 matrix (power iteration, slightly inflated).
float spectralNorm(const Mat3& m);

/// True when the box is unbounded in some axis (a bare cutter's support).
inline bool isHuge(const Box3& b) {
  return b.empty() ? false : (b.hi.x - b.lo.x > 1e30f || b.hi.y - b.lo.y > 1e30f || b.hi.z - b.lo.z > 1e30f);
}
/// An unbounded box.
inline Box3 hugeBox() { return Box3{Vec3(-1e35f), Vec3(1e35f)}; }

}  // namespace sprig::blobtree::detail
