#include "blobtree/compiled.h"

#include "blobtree/detail/accel.h"
#include "blobtree/detail/batch_eval.h"
#include "blobtree/detail/gradient_eval.h"
#include "blobtree/detail/interval_eval.h"
#include "blobtree/detail/point_eval.h"
#include "blobtree/detail/tape.h"
#include "blobtree/detail/traverse.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace sprig::blobtree {

using namespace detail;

namespace {

// ---- Compilation ---------------------------------------------------------------------------

struct Compiler {
  const BlobTree& tree;
  Tape& T;
  std::unordered_map<NodeId, uint32_t> done;

  uint32_t visit(NodeId id) {
    if (auto it = done.find(id); it != done.end()) return it->second;
    const Node& src = tree.node(id);
    std::vector<uint32_t> kids;
    kids.reserve(src.children.size());
    for (NodeId c : src.children) kids.push_back(visit(c));
    TNode n;
    n.kind = src.kind;
    n.box = src.bounds;
    n.lip = src.lipschitz;
    n.weight = src.weight;
    n.exponent = src.exponent;
    if (isPrimitive(src.kind)) {
      n.prim = uint32_t(T.prims.size());
      T.prims.push_back(makePrim(src, tree.kernel()));
    } else {
      TParams P;
      if (src.kind == NodeKind::Pcm) P.pcm = derivePcm(src.pcm);
      if (src.kind == NodeKind::Transform) {
        P.localFromWorld = src.localFromWorld;
        P.worldFromLocal = src.worldFromLocal;
        P.jt = glm::transpose(Mat3(src.localFromWorld));
        P.jNorm = spectralNorm(Mat3(src.localFromWorld));
      }
      if (src.kind == NodeKind::Bend) P.bend = makeBendFrame(src.bend, tree.node(src.children[0]).bounds);
      P.twist = src.twist;
      P.taper = src.taper;
      n.prim = uint32_t(T.params.size());
      T.params.push_back(P);
    }
    n.first = uint32_t(T.kids.size());
    n.count = uint32_t(kids.size());
    T.kids.insert(T.kids.end(), kids.begin(), kids.end());
    bool nary = src.kind == NodeKind::Blend || src.kind == NodeKind::Ricci || src.kind == NodeKind::Union ||
                src.kind == NodeKind::Pcm;
    if (nary && kids.size() >= kBvhMinChildren) {
      std::vector<Box3> boxes;
      for (uint32_t k : kids) boxes.push_back(T.nodes[k].box);
      n.bvh = buildBvh(T, boxes, kids);
      n.grid = buildGrid(T, boxes, kids);
    }
    uint32_t idx = uint32_t(T.nodes.size());
    T.nodes.push_back(n);
    done[id] = idx;
    return idx;
  }

  /// Forward (local to world) box map of a warp/transform node.
  Box3 forward(const TNode& n, const Box3& b) const {
    switch (n.kind) {
      case NodeKind::Transform: return transformBox(params(T, n).worldFromLocal, b);
      case NodeKind::Bend: return params(T, n).bend.worldBox(b);
      case NodeKind::Twist: {
        float h0, h1, r;
        axialExtent(b, params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r);
        return isHuge(b) ? b : cylinderBox(params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r);
      }
      case NodeKind::Taper: {
        float h0, h1, r;
        axialExtent(b, params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r);
        float smax = std::max(taperScale(params(T, n).taper, h0), taperScale(params(T, n).taper, h1));
        return isHuge(b) ? b : cylinderBox(params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r * smax);
      }
      default: return b;
    }
  }

  void instances(uint32_t ni, std::vector<uint32_t>& chain, const Box3& clip) {
    const TNode& n = T.nodes[ni];
    if (isPrimitive(n.kind)) {
      Box3 b = n.box;
      for (size_t k = chain.size(); k-- > 0;) b = forward(T.nodes[chain[k]], b);
      b = b.intersected(clip);
      if (b.empty()) return;
      T.instBox.push_back(b);
      T.instPrim.push_back(n.prim);
      return;
    }
    bool warp = n.kind == NodeKind::Transform || n.kind == NodeKind::Bend || n.kind == NodeKind::Twist ||
                n.kind == NodeKind::Taper;
    if (warp) chain.push_back(ni);
    for (uint32_t k = 0; k < n.count; ++k) instances(T.kids[n.first + k], chain, clip);
    if (warp) chain.pop_back();
  }
};

}  // namespace

// ---- CompiledBlob ------------------------------------------------------------------------

CompiledBlob::CompiledBlob() : tape_(std::make_shared<Tape>()) {}
CompiledBlob::~CompiledBlob() = default;
CompiledBlob::CompiledBlob(const CompiledBlob&) = default;
CompiledBlob& CompiledBlob::operator=(const CompiledBlob&) = default;
CompiledBlob::CompiledBlob(CompiledBlob&&) noexcept = default;
CompiledBlob& CompiledBlob::operator=(CompiledBlob&&) noexcept = default;

CompiledBlob compile(const BlobTree& tree, NodeId root) {
  if (root >= tree.size()) throw std::invalid_argument("compile: unknown root node");
  auto tape = std::make_shared<Tape>();
  Compiler c{tree, *tape, {}};
  tape->root = c.visit(root);
  tape->empty = false;
  std::vector<uint32_t> chain;
  c.instances(tape->root, chain, tape->nodes[tape->root].box);
  if (!tape->instBox.empty()) {
    std::vector<uint32_t> items(tape->instBox.size());
    std::iota(items.begin(), items.end(), 0u);
    tape->instBvh = buildBvh(*tape, tape->instBox, items);
  }
  float mf = 0.0f;
  for (const Prim& P : tape->prims)
    if (P.isoRadiusMin > 0.0f) mf = mf == 0.0f ? P.isoRadiusMin : std::min(mf, P.isoRadiusMin);
  tape->minFeature = mf;
  CompiledBlob b;
  b.tape_ = std::move(tape);
  return b;
}

float CompiledBlob::value(Vec3 p) const { return tape_->empty ? 0.0f : evalV(*tape_, tape_->root, p, true); }
float CompiledBlob::valueNoCulling(Vec3 p) const { return tape_->empty ? 0.0f : evalV(*tape_, tape_->root, p, false); }

Vec3 CompiledBlob::gradient(Vec3 p) const { return tape_->empty ? Vec3(0.0f) : evalS(*tape_, tape_->root, p).g; }

Sample CompiledBlob::sample(Vec3 p) const {
  Sample s;
  if (tape_->empty) return s;
  SV r = evalS(*tape_, tape_->root, p);
  s.value = r.v;
  s.gradient = r.g;
  if (r.acc.wSum > 0.0f) {
    s.attributes.uv = r.acc.uvSum / r.acc.wSum;
    // Sort textures by decreasing weight; normalize.
    std::array<int, Attributes::kMaxTextures> order{0, 1, 2, 3};
    for (int i = 1; i < r.acc.count; ++i)  // insertion sort, at most 4 entries
      for (int j = i; j > 0 && r.acc.w[size_t(order[size_t(j)])] > r.acc.w[size_t(order[size_t(j - 1)])]; --j)
        std::swap(order[size_t(j)], order[size_t(j - 1)]);
    float total = 0.0f;
    for (int i = 0; i < r.acc.count; ++i) total += r.acc.w[size_t(i)];
    for (int i = 0; i < r.acc.count; ++i) {
      s.attributes.textureIds[size_t(i)] = r.acc.ids[size_t(order[size_t(i)])];
      s.attributes.textureWeights[size_t(i)] = r.acc.w[size_t(order[size_t(i)])] / total;
    }
    s.attributes.textureCount = uint8_t(r.acc.count);
  }
  return s;
}

void CompiledBlob::values(std::span<const Vec3> points, std::span<float> out) const {
  assert(out.size() >= points.size());
  if (tape_->empty) {
    std::fill(out.begin(), out.begin() + long(points.size()), 0.0f);
    return;
  }
  evalBatch(*tape_, points, out);
}

void CompiledBlob::valuesInCell(const Cell& cell, std::span<const Vec3> points, std::span<float> out) const {
  (void)cell;  // the batch's own bounding box (inside the cell) culls at least as well
  values(points, out);
}

Box3 CompiledBlob::bounds() const { return tape_->empty ? Box3{} : tape_->nodes[tape_->root].box; }

Interval CompiledBlob::valueBounds(const Box3& box) const {
  return tape_->empty ? Interval{} : evalI(*tape_, tape_->root, box);
}

float CompiledBlob::lipschitz(const Box3& box) const { return tape_->empty ? 0.0f : evalL(*tape_, tape_->root, box); }
float CompiledBlob::lipschitz() const { return tape_->empty ? 0.0f : tape_->nodes[tape_->root].lip; }

size_t CompiledBlob::primitiveCount() const { return tape_->instBox.size(); }
Box3 CompiledBlob::primitiveBounds(uint32_t i) const { return tape_->instBox.at(i); }
float CompiledBlob::smallestFeature() const { return tape_->minFeature; }

// ---- Ray intersection ------------------------------------------------------------------------

namespace {

float modelSize(const Tape& T) {
  const Box3& b = T.nodes[T.root].box;
  if (b.empty() || isHuge(b)) return 1.0f;
  return std::max(glm::length(b.size()), 1e-20f);
}

/// Clips [s0, s1] of a unit-direction ray to box; false when empty.
bool clipToBox(const Box3& b, Vec3 o, Vec3 d, float& s0, float& s1) {
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-30f) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
      continue;
    }
    float inv = 1.0f / d[a];
    float ta = (b.lo[a] - o[a]) * inv, tb = (b.hi[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    s0 = std::max(s0, ta);
    s1 = std::min(s1, tb);
    if (s0 > s1) return false;
  }
  return true;
}

/// Refines a bracketed crossing of F − iso in [a, b] (fa, fb on opposite sides) by the
/// Illinois variant of regula falsi with a bisection safeguard.
float refine(const CompiledBlob& blob, Vec3 o, Vec3 d, float a, float b, float fa, float fb, float tol) {
  fa -= kIso;
  fb -= kIso;
  int side = 0;
  for (int it = 0; it < 60 && b - a > tol; ++it) {
    float m = (it % 4 == 3) ? 0.5f * (a + b) : (a * fb - b * fa) / (fb - fa);
    if (!(m > a && m < b)) m = 0.5f * (a + b);
    float fm = blob.value(o + m * d) - kIso;
    if ((fm > 0.0f) == (fa > 0.0f)) {
      a = m;
      fa = fm;
      if (side == -1) fb *= 0.5f;
      side = -1;
    } else {
      b = m;
      fb = fm;
      if (side == 1) fa *= 0.5f;
      side = 1;
    }
  }
  return std::abs(fa) < std::abs(fb) ? a : b;
}

std::optional<Hit> makeHit(const CompiledBlob& blob, const Ray& ray, Vec3 o, Vec3 d, float s, float dirLen) {
  Hit h;
  h.t = s / dirLen;
  h.point = o + s * d;
  Sample smp = blob.sample(h.point);
  float gl = glm::length(smp.gradient);
  h.normal = gl > 0.0f ? -smp.gradient / gl : -d;
  h.attributes = smp.attributes;
  (void)ray;
  return h;
}

}  // namespace

std::optional<Hit> CompiledBlob::intersect(const Ray& ray, float tmin, float tmax, const TraceOptions& opt) const {
  if (tape_->empty) return std::nullopt;
  float dirLen = glm::length(ray.direction);
  if (!(dirLen > 0.0f)) return std::nullopt;
  Vec3 d = ray.direction / dirLen, o = ray.origin;
  float s0 = tmin * dirLen, s1 = tmax * dirLen;
  Box3 root = bounds();
  if (!isHuge(root) && !clipToBox(root, o, d, s0, s1)) return std::nullopt;
  if (!(s1 > s0) && !(s1 == s0)) return std::nullopt;
  float size = isHuge(root) ? std::max(1.0f, s1 - s0) : modelSize(*tape_);
  float eps = std::max(opt.relativeTolerance * size, 1e-30f);
  float s = s0;
  float f = value(o + s * d);
  bool inside = f > kIso;
  float W = std::max(s1 - s0, eps);
  float wMin = 4.0f * eps;
  for (int step = 0; step < opt.maxSteps; ++step) {
    if (s >= s1) return std::nullopt;
    W = std::min(W, s1 - s);
    Vec3 pa = o + s * d, pb = o + (s + W) * d;
    Box3 box{glm::min(pa, pb), glm::max(pa, pb)};
    Interval iv = valueBounds(box);
    if ((!inside && iv.hi < kIso) || (inside && iv.lo > kIso)) {
      s += W;
      if (s >= s1) return std::nullopt;
      f = value(o + s * d);
      W *= 2.0f;
      continue;
    }
    float L = lipschitz(box);
    float safe = L > 0.0f ? std::abs(f - kIso) / L : W;
    if (safe >= W) {
      s += W;
      if (s >= s1) return std::nullopt;
      f = value(o + s * d);
      W *= 2.0f;
      continue;
    }
    if (W > 4.0f * safe && W > wMin) {
      W = std::max(4.0f * safe, wMin);
      continue;
    }
    if (safe < eps) {
      float s2 = std::min(s + 2.0f * eps, s1);
      float f2 = value(o + s2 * d);
      if ((f2 > kIso) != inside) return makeHit(*this, ray, o, d, refine(*this, o, d, s, s2, f, f2, eps * 1e-3f), dirLen);
      s = s2;
      f = f2;
      continue;
    }
    s += safe;
    f = value(o + s * d);
    if ((f > kIso) != inside) {
      // A crossing can only be reached at the end of a safe step when |f − iso| was 0.
      return makeHit(*this, ray, o, d, s, dirLen);
    }
  }
  return std::nullopt;
}

std::optional<Hit> CompiledBlob::intersectCell(const Cell& cell, const Ray& ray, float tmin, float tmax,
                                               const TraceOptions& opt) const {
  if (tape_->empty) return std::nullopt;
  float dirLen = glm::length(ray.direction);
  if (!(dirLen > 0.0f)) return std::nullopt;
  Vec3 d = ray.direction / dirLen, o = ray.origin;
  float s0 = tmin * dirLen, s1 = tmax * dirLen;
  if (!clipToBox(cell.box, o, d, s0, s1)) return std::nullopt;
  float eps = std::max(opt.relativeTolerance * modelSize(*tape_), 1e-30f);
  float L = std::max(cell.lipschitz, 1e-30f);
  float s = s0;
  float f = value(o + s * d);
  bool inside = f > kIso;
  for (int step = 0; step < opt.maxSteps; ++step) {
    float safe = std::abs(f - kIso) / L;
    if (s + safe > s1) return std::nullopt;
    if (safe < eps) {
      float s2 = s + 2.0f * eps;
      if (s2 > s1) s2 = s1;
      if (s2 <= s) return std::nullopt;
      float f2 = value(o + s2 * d);
      if ((f2 > kIso) != inside) return makeHit(*this, ray, o, d, refine(*this, o, d, s, s2, f, f2, eps * 1e-3f), dirLen);
      s = s2;
      f = f2;
      continue;
    }
    s += safe;
    f = value(o + s * d);
    if ((f > kIso) != inside) return makeHit(*this, ray, o, d, s, dirLen);
  }
  return std::nullopt;
}

}  // namespace sprig::blobtree
