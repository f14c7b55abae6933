#include "blobtree/compiled.h"

#include "blobtree/detail/accel.h"
#include "blobtree/detail/batch_eval.h"
#include "blobtree/detail/batch_grad_eval.h"
#include "blobtree/detail/gradient_eval.h"
#include "blobtree/detail/interval_eval.h"
#include "blobtree/detail/point_eval.h"
#include "blobtree/detail/tape.h"
#include "blobtree/detail/traverse.h"

#include <algorithm>
#include <cassert>
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
  float mf = 0.0f, ml = 0.0f;
  for (const Prim& P : tape->prims) {
    if (P.tex.relief) continue;
    if (P.isoRadiusMin > 0.0f) mf = mf == 0.0f ? P.isoRadiusMin : std::min(mf, P.isoRadiusMin);
    if (P.isoRadiusMax > 0.0f) ml = ml == 0.0f ? P.isoRadiusMax : std::min(ml, P.isoRadiusMax);
  }
  tape->minFeature = mf;
  tape->minLimb = ml;
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
    // Layers: by decreasing weight (ties keep their order: deterministic), normalized.
    std::array<Attributes::Layer, Attributes::kMaxLayers> layers = r.acc.layers;
    const int n = r.acc.layerCount;
    std::stable_sort(layers.begin(), layers.begin() + n,
                     [](const Attributes::Layer& a, const Attributes::Layer& b) { return a.weight > b.weight; });
    float layerTotal = 0.0f;
    for (int i = 0; i < n; ++i) layerTotal += layers[size_t(i)].weight;
    for (int i = 0; i < n; ++i) {
      s.attributes.layers[size_t(i)] = layers[size_t(i)];
      s.attributes.layers[size_t(i)].weight /= layerTotal;
    }
    s.attributes.layerCount = uint8_t(n);
    s.attributes.contact = r.acc.contact;
    s.attributes.contactGradient = r.acc.contactGrad;
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

void CompiledBlob::valuesAndGradients(std::span<const Vec3> points, std::span<float> out,
                                      std::span<Vec3> gradients) const {
  assert(out.size() >= points.size() && gradients.size() >= points.size());
  if (tape_->empty) {
    std::fill(out.begin(), out.begin() + long(points.size()), 0.0f);
    std::fill(gradients.begin(), gradients.begin() + long(points.size()), Vec3(0.0f));
    return;
  }
  evalBatchGradient(*tape_, points, out, gradients);
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
size_t CompiledBlob::nodeCount() const { return tape_->empty ? 0 : tape_->nodes.size(); }
float CompiledBlob::smallestFeature() const { return tape_->minFeature; }
float CompiledBlob::thinnestLimb() const { return tape_->minLimb; }

}  // namespace sprig::blobtree
