#include "blobtree/blobtree.h"

#include "blobtree/detail/field.h"

#include <glm/gtc/matrix_transform.hpp>

#include "core/diagnostics.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sprig::blobtree {

using namespace detail;

float supportRadius(Kernel kernel, float isoRadius) {
  return kernel == Kernel::Wyvill ? isoRadius / kWyvillIso : 2.0f * isoRadius;
}
float kernelValue(Kernel kernel, float s) { return s >= 1.0f ? 0.0f : kernelG(kernel, std::max(s, 0.0f)); }
float kernelSlope(Kernel kernel) { return kernel == Kernel::Wyvill ? kWyvillSlope : kSoftSlope; }

// ---- Public helpers -------------------------------------------------------------------------

float pcmDeform(const PcmParams& params, float fOther) { return pcmD(derivePcm(params), fOther, nullptr); }
float pcmDeformDerivative(const PcmParams& params, float fOther) {
  float d;
  pcmD(derivePcm(params), fOther, &d);
  return d;
}
float pcmBulgeMax(const PcmParams& params) { return derivePcm(params).a0; }

Bend Bend::fromAngle(Vec3 a, Vec3 b, Vec3 direction, float angleRad) {
  Bend r;
  r.a = a;
  r.b = b;
  r.direction = direction;
  float L = glm::length(b - a);
  float phi = 0.5f * angleRad;
  if (phi <= 0.0f) return r;
  float rho = 0.5f * L / std::sin(phi);
  r.sagitta = rho * (1.0f - std::cos(phi));
  return r;
}
float Bend::radius() const {
  float L = glm::length(b - a);
  return sagitta > 0.0f ? (0.25f * L * L + sagitta * sagitta) / (2.0f * sagitta) : std::numeric_limits<float>::infinity();
}
Vec3 Bend::worldFromLocal(Vec3 local) const { return makeBendFrame(*this, Box3{}).worldFromLocal(local); }
Vec3 Bend::localFromWorld(Vec3 world) const { return makeBendFrame(*this, Box3{}).localFromWorld(world); }

// ---- Builder --------------------------------------------------------------------------------

const Node& BlobTree::node(NodeId id) const {
  assert(id < nodes_.size());
  return nodes_[id];
}

void BlobTree::fail(const std::string& message) const { throw InputError(loc_, "blobtree: " + message); }

void BlobTree::check(NodeId id) const {
  if (id >= nodes_.size()) fail("unknown node id " + std::to_string(id));
}

namespace {
bool finitePositive(float v) { return std::isfinite(v) && v > 0.0f; }
bool finiteVec(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// A primitive node of kind with its geometry fields (see Node) and texture.
Node primitiveNode(NodeKind kind, Vec3 p0, Vec3 p1, float ra, float rb, TextureAttr tex = {}) {
  return Node{.kind = kind, .p0 = p0, .p1 = p1, .ra = ra, .rb = rb, .texture = tex};
}

/// An operator node of kind over children.
Node operatorNode(NodeKind kind, std::span<const NodeId> children) {
  Node n;
  n.kind = kind;
  n.children.assign(children.begin(), children.end());
  return n;
}

/// An operator node of kind over one child (negative, transforms, warps).
Node unaryNode(NodeKind kind, NodeId child) { return operatorNode(kind, std::span<const NodeId>(&child, 1)); }
}  // namespace

NodeId BlobTree::add(Node n) {
  if (nodes_.size() >= kMaxBlobNodes)
    throw InputError(SourceLoc{}, "the BlobTree has more than " + std::to_string(kMaxBlobNodes) +
                                      " nodes (the limit, kMaxBlobNodes in blobtree/blobtree.h): use fewer derivation steps (steps:, --steps) or a smaller model");
  auto childBox = [&](size_t i) { return nodes_[n.children[i]].bounds; };
  auto childLip = [&](size_t i) { return nodes_[n.children[i]].lipschitz; };
  for (NodeId c : n.children) check(c);
  n.bounds = Box3{};
  n.lipschitz = 0.0f;
  if (isPrimitive(n.kind)) {
    Prim P = makePrim(n, kernel_);
    n.bounds = P.box;
    n.lipschitz = P.lipschitz;
  } else {
    switch (n.kind) {
      case NodeKind::Blend:
      case NodeKind::Ricci:
      case NodeKind::Pcm:
        for (size_t i = 0; i < n.children.size(); ++i) {
          n.bounds.extend(childBox(i));
          n.lipschitz += childLip(i);
        }
        if (n.kind == NodeKind::Pcm) n.lipschitz *= 1.0f + derivePcm(n.pcm).maxSlope;
        break;
      case NodeKind::Union:
        for (size_t i = 0; i < n.children.size(); ++i) {
          n.bounds.extend(childBox(i));
          n.lipschitz = std::max(n.lipschitz, childLip(i));
        }
        break;
      case NodeKind::Intersect:
        n.bounds = n.children.empty() ? Box3{} : childBox(0);
        for (size_t i = 0; i < n.children.size(); ++i) {
          n.bounds = n.bounds.intersected(childBox(i));
          n.lipschitz = std::max(n.lipschitz, childLip(i));
        }
        if (n.bounds.empty()) n.bounds = Box3{};
        break;
      case NodeKind::Difference:
        n.bounds = childBox(0);
        n.lipschitz = std::max(childLip(0), childLip(1));
        break;
      case NodeKind::Negative:
        n.bounds = childBox(0);
        n.lipschitz = std::abs(n.weight) * childLip(0);
        break;
      case NodeKind::Transform:
        n.bounds = transformBox(n.worldFromLocal, childBox(0));
        n.lipschitz = childLip(0) * spectralNorm(Mat3(n.localFromWorld));
        break;
      case NodeKind::Bend: {
        BendFrame f;
        try {
          f = makeBendFrame(n.bend, childBox(0));
        } catch (const std::invalid_argument& e) {
          fail(e.what());
        }
        n.bounds = f.worldBox(childBox(0));
        n.lipschitz = childLip(0) * f.jacobianBound(n.bounds);
        break;
      }
      case NodeKind::Twist: {
        float h0, h1, r;
        axialExtent(childBox(0), n.twist.origin, n.twist.axis, h0, h1, r);
        n.bounds = isHuge(childBox(0)) ? childBox(0) : cylinderBox(n.twist.origin, n.twist.axis, h0, h1, r);
        n.lipschitz = childLip(0) * (1.0f + std::abs(n.twist.rateRadPerUnit) * r);
        break;
      }
      case NodeKind::Taper: {
        float h0, h1, r;
        axialExtent(childBox(0), n.taper.origin, n.taper.axis, h0, h1, r);
        float s0 = taperScale(n.taper, h0), s1 = taperScale(n.taper, h1);
        if (!(s0 > 0.0f && s1 > 0.0f)) fail("taper: the scale must stay positive over the child's support");
        float smin = std::min(s0, s1), smax = std::max(s0, s1);
        n.bounds = isHuge(childBox(0)) ? childBox(0) : cylinderBox(n.taper.origin, n.taper.axis, h0, h1, r * smax);
        float ds = std::abs(n.taper.scale1 - n.taper.scale0) / n.taper.length;
        n.lipschitz = childLip(0) * (1.0f / smin + 1.0f + ds * r * smax / (smin * smin));
        break;
      }
      default: break;
    }
  }
  nodes_.push_back(std::move(n));
  return NodeId(nodes_.size() - 1);
}

NodeId BlobTree::point(Vec3 center, float radius, TextureAttr tex) {
  if (!finiteVec(center) || !finitePositive(radius)) fail("point: radius must be positive and finite");
  return add(primitiveNode(NodeKind::Point, center, Vec3(0.0f), radius, 0.0f, tex));
}

NodeId BlobTree::segment(Vec3 a, Vec3 b, float radius, TextureAttr tex) {
  if (!finiteVec(a) || !finiteVec(b) || !finitePositive(radius)) fail("segment: radius must be positive and finite");
  if (!(glm::length(b - a) > 0.0f)) fail("segment: the endpoints coincide");
  return add(primitiveNode(NodeKind::Segment, a, b, radius, radius, tex));
}

NodeId BlobTree::cone(Vec3 a, Vec3 b, float radiusA, float radiusB, TextureAttr tex) {
  if (!finiteVec(a) || !finiteVec(b) || !finitePositive(radiusA) || !finitePositive(radiusB))
    fail("cone: radii must be positive and finite");
  if (!(glm::length(b - a) > 0.0f)) fail("cone: the endpoints coincide");
  return add(primitiveNode(NodeKind::Cone, a, b, radiusA, radiusB, tex));
}

NodeId BlobTree::torus(Vec3 center, Vec3 axis, float majorRadius, float minorRadius, TextureAttr tex) {
  if (!finiteVec(center) || !finitePositive(majorRadius) || !finitePositive(minorRadius))
    fail("torus: radii must be positive and finite");
  if (!(glm::length(axis) > 0.0f)) fail("torus: the axis is zero");
  return add(primitiveNode(NodeKind::Torus, center, glm::normalize(axis), majorRadius, minorRadius, tex));
}

NodeId BlobTree::halfspace(Vec3 point, Vec3 normal, float ramp) {
  if (!finiteVec(point) || !(glm::length(normal) > 0.0f)) fail("halfspace: the normal is zero");
  if (!finitePositive(ramp)) fail("halfspace: ramp must be positive");
  return add(primitiveNode(NodeKind::Halfspace, point, glm::normalize(normal), ramp, 0.0f));
}

NodeId BlobTree::box(Vec3 lo, Vec3 hi, float ramp) {
  if (!finiteVec(lo) || !finiteVec(hi) || !(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) fail("box: need lo < hi on every axis");
  if (!finitePositive(ramp)) fail("box: ramp must be positive");
  return add(primitiveNode(NodeKind::Box, lo, hi, ramp, 0.0f));
}

NodeId BlobTree::setWeight(NodeId primitive, float weight) {
  check(primitive);
  Node& n = nodes_[primitive];
  if (!isPrimitive(n.kind)) fail("setWeight: node is not a primitive");
  if (!std::isfinite(weight)) fail("setWeight: weight must be finite");
  n.weight = weight;
  Prim P = makePrim(n, kernel_);
  n.bounds = P.box;
  n.lipschitz = P.lipschitz;
  return primitive;
}

NodeId BlobTree::blend(std::span<const NodeId> children) {
  return add(operatorNode(NodeKind::Blend, children));
}

NodeId BlobTree::ricci(std::span<const NodeId> children, float exponent) {
  if (!(std::isfinite(exponent) && exponent >= 1.0f)) fail("ricci: n must be >= 1");
  Node n = operatorNode(NodeKind::Ricci, children);
  n.exponent = exponent;
  return add(std::move(n));
}

NodeId BlobTree::unite(std::span<const NodeId> children) {
  return add(operatorNode(NodeKind::Union, children));
}

NodeId BlobTree::intersect(std::span<const NodeId> children) {
  if (children.empty()) fail("intersect: needs at least one child");
  return add(operatorNode(NodeKind::Intersect, children));
}

NodeId BlobTree::difference(NodeId a, NodeId b) {
  Node n;
  n.kind = NodeKind::Difference;
  n.children = {a, b};
  return add(std::move(n));
}

NodeId BlobTree::controlledBlend(std::span<const NodeId> children, const std::vector<std::vector<uint32_t>>& groups) {
  std::vector<bool> grouped(children.size(), false);
  std::vector<NodeId> parts;
  for (const auto& g : groups) {
    std::vector<NodeId> members;
    for (uint32_t i : g) {
      if (i >= children.size()) fail("controlledBlend: group index " + std::to_string(i) + " out of range");
      members.push_back(children[i]);
      grouped[i] = true;
    }
    if (members.empty()) continue;
    parts.push_back(members.size() == 1 ? members[0] : blend(members));
  }
  for (size_t i = 0; i < children.size(); ++i)
    if (!grouped[i]) parts.push_back(children[i]);
  return unite(parts);
}

NodeId BlobTree::pcm(std::span<const NodeId> children, PcmParams params) {
  if (!(params.width > 0.0f && params.width <= params.iso)) fail("pcm: width must be in (0, iso]");
  if (!(params.slope >= 0.0f && std::isfinite(params.slope))) fail("pcm: slope must be >= 0");
  if (!(params.bulgeScale >= 0.0f && std::isfinite(params.bulgeScale))) fail("pcm: bulgeScale must be >= 0");
  Node n = operatorNode(NodeKind::Pcm, children);
  n.pcm = params;
  return add(std::move(n));
}

NodeId BlobTree::pcm(NodeId a, NodeId b, PcmParams params) {
  NodeId c[2] = {a, b};
  return pcm(std::span<const NodeId>(c, 2), params);
}

NodeId BlobTree::negative(NodeId child, float weight) {
  if (!(std::isfinite(weight) && weight >= 0.0f)) fail("negative: weight must be >= 0");
  Node n = unaryNode(NodeKind::Negative, child);
  n.weight = weight;
  return add(std::move(n));
}

NodeId BlobTree::transform(NodeId child, const Mat4& worldFromLocal) {
  float det = glm::determinant(worldFromLocal);
  if (!std::isfinite(det) || std::abs(det) < 1e-12f) fail("transform: the matrix is not invertible");
  Node n = unaryNode(NodeKind::Transform, child);
  n.worldFromLocal = worldFromLocal;
  n.localFromWorld = glm::inverse(worldFromLocal);
  return add(std::move(n));
}

NodeId BlobTree::translate(NodeId child, Vec3 offset) { return transform(child, glm::translate(Mat4(1.0f), offset)); }
NodeId BlobTree::scale(NodeId child, Vec3 factors) { return transform(child, glm::scale(Mat4(1.0f), factors)); }
NodeId BlobTree::rotate(NodeId child, Vec3 axis, float angleRad) {
  if (!(glm::length(axis) > 0.0f)) fail("rotate: the axis is zero");
  return transform(child, glm::rotate(Mat4(1.0f), angleRad, glm::normalize(axis)));
}

NodeId BlobTree::bend(NodeId child, const Bend& b) {
  if (!(b.sagitta >= 0.0f && std::isfinite(b.sagitta))) fail("bend: sagitta must be >= 0");
  if (!(glm::length(b.b - b.a) > 0.0f)) fail("bend: the segment a-b has zero length");
  if (b.sagitta > glm::length(b.b - b.a)) fail("bend: sagitta must not exceed the chord length");
  Node n = unaryNode(NodeKind::Bend, child);
  n.bend = b;
  return add(std::move(n));
}

NodeId BlobTree::bend(NodeId child, Vec3 a, Vec3 b, float sagitta, Vec3 direction) {
  Bend bd;
  bd.a = a;
  bd.b = b;
  bd.sagitta = sagitta;
  bd.direction = direction;
  return bend(child, bd);
}

NodeId BlobTree::twist(NodeId child, const Twist& t) {
  if (!(glm::length(t.axis) > 0.0f)) fail("twist: the axis is zero");
  Node n = unaryNode(NodeKind::Twist, child);
  n.twist = t;
  n.twist.axis = glm::normalize(t.axis);
  return add(std::move(n));
}

NodeId BlobTree::taper(NodeId child, const Taper& t) {
  if (!(glm::length(t.axis) > 0.0f)) fail("taper: the axis is zero");
  if (!finitePositive(t.length)) fail("taper: length must be positive");
  Node n = unaryNode(NodeKind::Taper, child);
  n.taper = t;
  n.taper.axis = glm::normalize(t.axis);
  return add(std::move(n));
}

// ---- Reference evaluator ------------------------------------------------------------------

float BlobTree::value(NodeId id, Vec3 p) const {
  check(id);
  const Node& n = nodes_[id];
  if (isPrimitive(n.kind)) return primValue(makePrim(n, kernel_), p, nullptr);
  switch (n.kind) {
    case NodeKind::Blend: {
      float s = 0.0f;
      for (NodeId c : n.children) s += value(c, p);
      return s;
    }
    case NodeKind::Ricci: {
      float m = 0.0f, sum = 0.0f;
      for (NodeId c : n.children) {
        float f = std::max(0.0f, value(c, p));
        if (f <= 0.0f) continue;
        if (f > m) {
          sum = (m > 0.0f ? sum * std::pow(m / f, n.exponent) : 0.0f) + 1.0f;
          m = f;
        } else {
          sum += std::pow(f / m, n.exponent);
        }
      }
      return m > 0.0f ? m * std::pow(sum, 1.0f / n.exponent) : 0.0f;
    }
    case NodeKind::Union: {
      float m = 0.0f;
      for (NodeId c : n.children) m = std::max(m, value(c, p));
      return m;
    }
    case NodeKind::Intersect: {
      float m = std::numeric_limits<float>::max();
      for (NodeId c : n.children) m = std::min(m, value(c, p));
      return std::max(0.0f, m);
    }
    case NodeKind::Difference:
      return std::max(0.0f, std::min(value(n.children[0], p), 1.0f - value(n.children[1], p)));
    case NodeKind::Pcm: {
      PcmDerived d = derivePcm(n.pcm);
      PcmAccum acc;
      for (NodeId c : n.children) {
        float f = std::max(0.0f, value(c, p));
        acc.add(f, pcmD(d, f, nullptr));
      }
      return acc.value();
    }
    case NodeKind::Negative: return -n.weight * value(n.children[0], p);
    case NodeKind::Transform: return value(n.children[0], Vec3(n.localFromWorld * Vec4(p, 1.0f)));
    case NodeKind::Bend:
      return value(n.children[0], makeBendFrame(n.bend, nodes_[n.children[0]].bounds).localFromWorld(p));
    case NodeKind::Twist: return value(n.children[0], twistLocal(n.twist, p, nullptr));
    case NodeKind::Taper: return value(n.children[0], taperLocal(n.taper, p, nullptr));
    default: return 0.0f;
  }
}

}  // namespace sprig::blobtree
