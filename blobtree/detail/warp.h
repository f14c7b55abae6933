#pragma once
/// Private: the warps' maps: the endpoint-preserving bend's frame (point maps, box maps,
/// Jacobian bound), twist and taper.

#include "blobtree/blobtree.h"

namespace sprig::blobtree::detail {

/// Precomputed frame of an endpoint-preserving bend.
struct BendFrame {
  bool straight = true;
  Vec3 M{0.0f}, u{1.0f, 0.0f, 0.0f}, n{0.0f, 1.0f, 0.0f}, z{0.0f, 0.0f, 1.0f}, C{0.0f};
  float rho = 0.0f, stretch = 1.0f, phi = 0.0f;
  float yMinChild = 0.0f;  ///< child's support y lower bound in the frame (≥ −ρ)
  /// The image of the child's support as a box in the frame about C (along u, n and z),
  /// widened for rounding; bounded is false when no child box was given.
  bool bounded = false;
  float uLo = 0.0f, uHi = 0.0f, vLo = 0.0f, vHi = 0.0f, wLo = 0.0f, wHi = 0.0f;

  Vec3 localFromWorld(Vec3 p, Mat3* jacobianT = nullptr) const;
  /// localFromWorld of `count` points given as coordinate arrays; same bits as one by one.
  void localFromWorld(const float* x, const float* y, const float* z, float* lx, float* ly, float* lz,
                      int count) const;
  Vec3 worldFromLocal(Vec3 q) const;
  /// Local box of the child space covering the world box's preimage (conservative).
  Box3 localBox(const Box3& worldBox, const Box3& childBox) const;
  /// World box covering the image of the child's box.
  Box3 worldBox(const Box3& childBox) const;
  /// False when world point (x, y, z) lies outside the image of the child's support (so
  /// the child is 0 there): an oriented box test of 9 products, much cheaper than
  /// localFromWorld and tighter than worldBox for slanted bends. True when not bounded.
  bool mayReach(float x, float y, float z) const {
    if (!bounded) return true;
    const float rx = x - C.x, ry = y - C.y, rz = z - C.z;
    const float uu = rx * u.x + ry * u.y + rz * u.z;
    const float vv = rx * n.x + ry * n.y + rz * n.z;
    const float ww = rx * this->z.x + ry * this->z.y + rz * this->z.z;
    return uu >= uLo && uu <= uHi && vv >= vLo && vv <= vHi && ww >= wLo && ww <= wHi;
  }
  /// Sets the support box (bounded, uLo…wHi) from the child's support box; makeBendFrame
  /// calls it.
  void setSupport(const Box3& childBox);
  /// Bound on the norm of d(local)/d(world) over worldBox.
  float jacobianBound(const Box3& worldBox) const;
};
/// The frame of bend b applied to a child whose support box is childBox (for the
/// child's radial extent); throws std::invalid_argument with a reason when the child's
/// support would reach the bend centre or wrap past a half turn.
BendFrame makeBendFrame(const Bend& b, const Box3& childBox);

/// The bend's atan2: within 2.4e-7 relative of std::atan2 (exposed for its test).
float atan2Approx(float y, float x);
/// Twist map pieces.
Vec3 twistLocal(const Twist& t, Vec3 p, Mat3* jacobianT);
/// Taper map pieces.
Vec3 taperLocal(const Taper& t, Vec3 p, Mat3* jacobianT);
/// Taper scale at axial height h.
inline float taperScale(const Taper& t, float h) { return t.scale0 + (t.scale1 - t.scale0) * (h / t.length); }

}  // namespace sprig::blobtree::detail
