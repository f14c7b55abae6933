#pragma once
/// The BlobTree: a hierarchical skeletal implicit surface model (Wyvill, Guy, Galin),
/// as used in "BlobTree Trees" (Galbraith, MacMurchy, Wyvill; seed 003) §2-3 and in
/// "Modeling a Murex cabritii sea shell" (Galbraith, Prusinkiewicz, Wyvill; seed 000) §2.2.
///
/// Representation: a `BlobTree` is a builder that owns a flat pool of nodes addressed by
/// `NodeId`. Leaves are skeletal primitives whose fields lie in [0,1] with compact support;
/// inner nodes are operators (blends, CSG, PCM, warps, transforms). A node may be shared by
/// several parents (the pool is a DAG). Nodes are immutable once built; every node knows its
/// support box (outside it the node's field is exactly 0) and a global Lipschitz bound.
/// The surface is F = 0.5 (`kIso`), inside is F > 0.5.
///
/// Evaluate a tree through `compile()` (blobtree/compiled.h). `BlobTree::value` is the
/// plain reference evaluator that visits every node (slow; for tests and baselines).
///
/// Errors: builder functions throw `sprig::InputError` (with the optional SourceLoc the
/// caller passes, e.g. the YAML position) on invalid parameters: non-positive radii, a
/// degenerate segment, a bend whose support would cross the bend centre, unknown NodeIds.

#include "core/diagnostics.h"
#include "core/types.h"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace sprig::blobtree {

/// Index of a node in a BlobTree's pool.
using NodeId = uint32_t;

/// The iso value of every BlobTree surface.
inline constexpr float kIso = 0.5f;

/// Field kernel g(s), s = r²/R², chosen once per tree.
enum class Kernel : uint8_t {
  /// Wyvill: g(s) = (1−s)³. Iso radius 0.4542·R, Lipschitz 1.7173/R. Default.
  Wyvill,
  /// Soft objects (Wyvill, McPheeters, Wyvill 1986): g = 1 − 4/9 s³ + 17/9 s² − 22/9 s.
  /// Iso radius exactly R/2.
  SoftObject,
};

/// The support radius R whose kernel puts the 0.5 iso surface at distance `isoRadius`.
float supportRadius(Kernel kernel, float isoRadius);
/// The kernel value g(s) for s = r²/R² (0 for s >= 1).
float kernelValue(Kernel kernel, float s);
/// The largest |d g(r/R) / dr| · R over r: 1.7173 (Wyvill), 1.5834 (soft objects).
float kernelSlope(Kernel kernel);

/// Per-primitive texture attributes: which texture and how its natural (u,v) maps.
/// The attribute at a point is Σ fᵢ·Tᵢ / Σ fᵢ over contributing primitives (tree paper §3.7).
struct TextureAttr {
  uint16_t textureId = 0;     ///< index into the caller's texture table
  Vec2 uvScale{1.0f, 1.0f};   ///< uv = natural · uvScale + uvOffset
  Vec2 uvOffset{0.0f, 0.0f};
  float vOffset = 0.0f;       ///< added to a cone's natural v (world length from the tree root)
  /// Direction that defines u = 0 around a cone/segment/torus axis (projected
  /// perpendicular to the axis); zero picks a fixed perpendicular.
  Vec3 refDir{0.0f};
  /// A relief primitive: a detail raised on other primitives' surface (a bark ridge). It
  /// carries no attributes (the surface keeps the texture of what it lies on) and counts
  /// as neither a feature nor a limb for cell sizes (CompiledBlob::smallestFeature,
  /// thinnestLimb). Its field is an ordinary primitive's.
  bool relief = false;
};

/// Parameters of Precise Contact Modeling (Gascuel 1993; Cani-Gascuel 1998; tree paper Eq. 3).
///
/// The deformation of a field by another field f_other, with x = c − f_other (how far,
/// in field units, the point lies outside the other object):
///  - interpenetration (x < 0): d = x = c − f_other (compression; contact surface f = f_other);
///  - propagation (0 ≤ x < w): d = h(x), the C¹ piecewise cubic with h(0)=0, h'(0)=k,
///    h(w/2)=a₀, h'(w/2)=0, h(w)=0, h'(w)=0 (a bulge);
///  - elsewhere: d = 0.
/// With k = 1 the deformed field is C¹ across the contact boundary. a₀ is computed when
/// the node is built: a₀ = bulgeScale · k·w/4 (k·w/4 makes the first cubic a parabola,
/// the largest bulge without overshoot). The bulge is gated on the other object's
/// outside region: it is zero wherever f_other >= c, and zero wherever f_other <= c − w.
struct PcmParams {
  float width = 0.15f;      ///< w: propagation width, in field units (0 < w <= c)
  float slope = 1.0f;       ///< k: slope of h at the contact (1 gives a C¹ field)
  float bulgeScale = 1.0f;  ///< a₀ = bulgeScale · k·w/4
  float iso = kIso;         ///< c: the contact threshold
};

/// The PCM deformation term d(f_other) described at PcmParams (a₀ = params' value).
float pcmDeform(const PcmParams& params, float fOther);
/// d d/d f_other of pcmDeform.
float pcmDeformDerivative(const PcmParams& params, float fOther);
/// The maximum bulge a₀ of params.
float pcmBulgeMax(const PcmParams& params);

/// The endpoint-preserving bend of tree paper §3.6: the straight segment a→b is bent
/// into a circular arc through a and b in the plane spanned by (b−a) and `direction`,
/// bulging towards `direction` by `sagitta` (the arc's distance from the chord at its
/// middle). The child is stretched along the axis so its straight length maps onto the
/// arc length: a and b stay where they are. Radius ρ = (L²/4 + s²)/(2s) for chord L.
struct Bend {
  Vec3 a{0.0f}, b{0.0f, 1.0f, 0.0f};
  Vec3 direction{1.0f, 0.0f, 0.0f};  ///< bulge direction; made perpendicular to b−a
  float sagitta = 0.0f;              ///< 0 <= sagitta <= |b−a|/2 (half circle)

  /// A bend of total turning angle `angleRad` (the arc subtends angleRad; <= π).
  static Bend fromAngle(Vec3 a, Vec3 b, Vec3 direction, float angleRad);
  /// The bend radius ρ (infinite for sagitta 0).
  float radius() const;
  /// Maps an unbent (child-space) point to world space: worldFromLocal(a) == a, (b) == b.
  Vec3 worldFromLocal(Vec3 local) const;
  /// Maps a world point to the child's unbent space (inverse of worldFromLocal).
  Vec3 localFromWorld(Vec3 world) const;
};

/// Twist about an axis: a world point at axial height h is rotated by −rate·h before the
/// child is evaluated (the child appears twisted by +rate radians per unit length).
struct Twist {
  Vec3 origin{0.0f};
  Vec3 axis{0.0f, 1.0f, 0.0f};  ///< normalized on build
  float rateRadPerUnit = 0.0f;
};

/// Taper along an axis: the child's cross-section is scaled by s(h), linear in the axial
/// height h from scale0 at h=0 (at origin) to scale1 at h=length. s must stay positive
/// over the child's support (checked on build).
struct Taper {
  Vec3 origin{0.0f};
  Vec3 axis{0.0f, 1.0f, 0.0f};  ///< normalized on build
  float length = 1.0f;
  float scale0 = 1.0f, scale1 = 1.0f;
};

/// The node kinds. Primitives first.
enum class NodeKind : uint8_t {
  Point, Segment, Cone, Torus, Halfspace, Box,
  Blend, Ricci, Union, Intersect, Difference, Pcm, Negative,
  Transform, Bend, Twist, Taper,
};

/// True for the leaf kinds (Point .. Box).
constexpr bool isPrimitive(NodeKind k) { return k <= NodeKind::Box; }

/// One node of the pool. Fields a node does not use keep their defaults.
struct Node {
  NodeKind kind = NodeKind::Point;
  std::vector<NodeId> children;
  // Primitive geometry: point/segment/cone use p0 (and p1), ra (and rb) are 0.5-iso radii;
  // torus: p0 centre, p1 unit axis, ra major radius, rb minor (tube) radius;
  // halfspace: p0 point, p1 unit outward normal; box: p0 lo, p1 hi; ra = cutter ramp width.
  Vec3 p0{0.0f}, p1{0.0f};
  float ra = 0.0f, rb = 0.0f;
  float weight = 1.0f;  ///< primitive field multiplier; Negative: subtracted weight
  TextureAttr texture;
  // Operators.
  float exponent = 1.0f;  ///< Ricci n
  PcmParams pcm;
  Mat4 worldFromLocal{1.0f}, localFromWorld{1.0f};  ///< Transform
  Bend bend;
  Twist twist;
  Taper taper;
  // Derived on build.
  Box3 bounds;        ///< support box: the field is exactly 0 outside it
  float lipschitz = 0.0f;  ///< global Lipschitz bound of the field
};

/// Most nodes (primitives and operators) one BlobTree may hold: 4,194,304, about 1 GB of
/// nodes and compiled tape. BlobTree::add throws InputError beyond it, before allocating.
inline constexpr size_t kMaxBlobNodes = size_t(1) << 22;

/// Builder of BlobTree nodes. All radii are 0.5-iso radii in world units; the support
/// radius R is derived from the kernel (Wyvill R = r/0.4542, soft objects R = 2r).
/// Primitives' fields are weight·g(dist²/R²) (weight defaults to 1).
class BlobTree {
 public:
  /// A tree whose primitives use `kernel`.
  explicit BlobTree(Kernel kernel = Kernel::Wyvill) : kernel_(kernel) {}

  Kernel kernel() const { return kernel_; }
  /// Number of nodes in the pool.
  size_t size() const { return nodes_.size(); }
  /// The node `id` (asserts id < size()).
  const Node& node(NodeId id) const;
  /// The location attached to errors of later builder calls (e.g. the YAML key's position).
  void setSourceLoc(SourceLoc loc) { loc_ = std::move(loc); }

  // ---- Primitives ---------------------------------------------------------------------
  /// Sphere-like point primitive; natural uv: u = longitude/2π, v = colatitude/π.
  NodeId point(Vec3 center, float radius, TextureAttr tex = {});
  /// Segment (capsule) of constant iso radius; uv as for cone.
  NodeId segment(Vec3 a, Vec3 b, float radius, TextureAttr tex = {});
  /// Cone internode (tree paper Fig. 7): the support radius varies linearly along a→b so
  /// the 0.5 iso radius is radiusA at a and radiusB at b; spherical caps at the ends.
  /// Field g(d²/R(t)²) with t the clamped projection parameter and d the distance to
  /// the axis point at t. Natural uv: u = angle around the axis / 2π (from tex.refDir),
  /// v = distance along the axis from a + tex.vOffset.
  NodeId cone(Vec3 a, Vec3 b, float radiusA, float radiusB, TextureAttr tex = {});
  /// Torus of the given major radius and tube (iso) radius; uv: u around the axis, v
  /// around the tube.
  NodeId torus(Vec3 center, Vec3 axis, float majorRadius, float minorRadius, TextureAttr tex = {});
  /// CSG cutter: field clamp(0.5 − signedDistance/ramp, 0, 1) of the half-space behind
  /// `point` opposite to `normal` (1 inside, 0 outside, a linear ramp of width `ramp`
  /// centred on the plane; the iso surface is exactly the plane). Unbounded support.
  /// Carries no texture attributes.
  NodeId halfspace(Vec3 point, Vec3 normal, float ramp = 1e-3f);
  /// CSG cutter box [lo, hi]: field clamp(0.5 − sdBox/ramp, 0, 1) with the exact signed
  /// box distance; the iso surface is exactly the box.
  NodeId box(Vec3 lo, Vec3 hi, float ramp = 1e-3f);
  /// Sets a primitive's field weight (multiplier; default 1). Returns id.
  NodeId setWeight(NodeId primitive, float weight);

  // ---- Operators ----------------------------------------------------------------------
  /// Summation blend Σ fᵢ (n-ary).
  NodeId blend(std::span<const NodeId> children);
  /// Super-elliptic (Ricci) blend (Σ fᵢⁿ)^(1/n), n >= 1, computed as m·(Σ(fᵢ/m)ⁿ)^(1/n)
  /// with m = max fᵢ so n = 400 does not underflow (murex paper §2.2). Negative child
  /// fields count as 0.
  NodeId ricci(std::span<const NodeId> children, float n);
  /// CSG union max fᵢ (n-ary).
  NodeId unite(std::span<const NodeId> children);
  /// CSG intersection min fᵢ (n-ary).
  NodeId intersect(std::span<const NodeId> children);
  /// CSG difference min(f_a, 1 − f_b).
  NodeId difference(NodeId a, NodeId b);
  /// Controlled blending (murex paper §2.2): children blend only within the given groups
  /// (lists of indices into `children`, e.g. neighbour pairs {i, i+1}); overlaps between
  /// groups meet as a union. Realized as max over groups of the group's sum; a child in
  /// no group forms its own group.
  NodeId controlledBlend(std::span<const NodeId> children, const std::vector<std::vector<uint32_t>>& groups);
  /// Precise Contact Modeling of two or more objects (tree paper Eq. 3), d of PcmParams:
  /// F = f_max + Σ_{j≠max, f_j <= c} d(f_j) + min(0, c − f_second): every bulge adds, only
  /// the deepest compression counts, so F >= c inside every child (summed compressions
  /// opened voids where three objects interpenetrate; docs/BLOBTREE.md). For two objects
  /// F = f_max + d(f_other); each deformed object fᵢ + d(f_j) > c is disjoint from the
  /// other when slope <= 1 (the contact surface fᵢ = f_j).
  NodeId pcm(std::span<const NodeId> children, PcmParams params = {});
  /// Binary PCM.
  NodeId pcm(NodeId a, NodeId b, PcmParams params = {});
  /// Negative field −weight·f_child (scars; add it to a blend).
  NodeId negative(NodeId child, float weight = 1.0f);

  // ---- Warps and transforms ------------------------------------------------------------
  /// Affine transform: the child, modelled in local space, placed by worldFromLocal
  /// (must be invertible). Fields are not rescaled (a scaled sphere keeps its field shape).
  NodeId transform(NodeId child, const Mat4& worldFromLocal);
  /// Translate.
  NodeId translate(NodeId child, Vec3 offset);
  /// Uniform or non-uniform scale about the origin.
  NodeId scale(NodeId child, Vec3 factors);
  /// Rotation about an axis through the origin.
  NodeId rotate(NodeId child, Vec3 axis, float angleRad);
  /// Endpoint-preserving bend (see Bend). Throws when the child's support would reach the
  /// bend centre (support radius must stay below ρ) or wrap past a half turn.
  NodeId bend(NodeId child, const Bend& bend);
  /// Convenience: bend of a segment a→b by a sagitta towards direction.
  NodeId bend(NodeId child, Vec3 a, Vec3 b, float sagitta, Vec3 direction);
  /// Twist (see Twist).
  NodeId twist(NodeId child, const Twist& twist);
  /// Taper (see Taper).
  NodeId taper(NodeId child, const Taper& taper);

  /// Reference evaluation of node `id` at p: visits every node below it (no culling).
  /// O(size of the subtree); used by tests and as the brute-force baseline.
  float value(NodeId id, Vec3 p) const;

 private:
  NodeId add(Node n);
  void check(NodeId id) const;
  [[noreturn]] void fail(const std::string& message) const;

  Kernel kernel_;
  std::vector<Node> nodes_;
  SourceLoc loc_;
};

}  // namespace sprig::blobtree
