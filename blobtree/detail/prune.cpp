#include "blobtree/detail/prune.h"

#include "blobtree/detail/interval_eval.h"
#include "blobtree/detail/traverse.h"

namespace sprig::blobtree::detail {

namespace {

/// Writes the pruned subtree of node ni over box into key (pre-order: a primitive is its
/// base index; an operator is its base index, its kept child count, then the children).
class Pruner {
 public:
  Pruner(const Tape& T, std::vector<uint32_t>& key) : T_(T), key_(key) {}

  /// False (key restored) when node ni is zero over box. nonNeg: F >= 0 everywhere.
  bool visit(uint32_t ni, const Box3& box, bool& nonNeg) {
    const TNode& n = T_.nodes[ni];
    if (box.empty() || !box.overlaps(n.box)) return false;
    const size_t head = key_.size();
    key_.push_back(ni);
    if (isPrimitive(n.kind)) {
      nonNeg = T_.prim(n.prim).weight >= 0.0f;
      return true;
    }
    key_.push_back(0);  // child count, filled below
    uint32_t kept = 0;
    bool allNonNeg = true;
    auto keep = [&](uint32_t c, const Box3& b) {
      bool nn = true;
      if (!visit(c, b, nn)) return false;
      ++kept;
      allNonNeg = allNonNeg && nn;
      return true;
    };
    switch (n.kind) {
      case NodeKind::Blend:
      case NodeKind::Union:
      case NodeKind::Ricci:
      case NodeKind::Pcm: {
        childrenIn(T_, n, box, [&](uint32_t c) { keep(c, box); });
        if (kept == 0) return drop(head);
        key_[head + 1] = kept;
        // Sum of one term: 0 + f == f. Union and Ricci of one child give max(0, f).
        bool identity = kept == 1 && n.kind != NodeKind::Pcm && (n.kind == NodeKind::Blend || allNonNeg);
        if (identity) key_.erase(key_.begin() + long(head), key_.begin() + long(head) + 2);
        nonNeg = n.kind == NodeKind::Blend ? allNonNeg : true;
        return true;
      }
      case NodeKind::Intersect:
        for (uint32_t k = 0; k < n.count; ++k)
          if (!keep(T_.kids[n.first + k], box)) return drop(head);  // min(…, 0) clamps to 0
        key_[head + 1] = kept;
        nonNeg = true;
        return true;
      case NodeKind::Difference: {
        const uint32_t a = T_.kids[n.first], b = T_.kids[n.first + 1];
        if (!keep(a, box)) return drop(head);
        if (!keep(b, box)) {
          // max(0, min(fa, 1 − 0)) is fa where fa lies in [0, 1].
          Interval ia = evalI(T_, a, box);
          if (ia.lo >= 0.0f && ia.hi <= 1.0f) {
            key_.erase(key_.begin() + long(head), key_.begin() + long(head) + 2);
            nonNeg = true;
            return true;
          }
          key_.push_back(kPrunedEmpty);
        }
        key_[head + 1] = 2;
        nonNeg = true;
        return true;
      }
      case NodeKind::Negative:
        if (!keep(T_.kids[n.first], box)) return drop(head);
        key_[head + 1] = 1;
        nonNeg = n.weight <= 0.0f && allNonNeg;
        return true;
      case NodeKind::Transform:
      case NodeKind::Bend:
      case NodeKind::Twist:
      case NodeKind::Taper:
        if (!keep(T_.kids[n.first], localBoxOf(n, T_, box))) return drop(head);
        key_[head + 1] = 1;
        nonNeg = allNonNeg;
        return true;
      default:
        // An operator this pruner does not know: keep it whole (every child), which is exact.
        for (uint32_t k = 0; k < n.count; ++k) keepWhole(T_.kids[n.first + k]);
        key_[head + 1] = n.count;
        nonNeg = false;
        return true;
    }
  }

 private:
  bool drop(size_t head) {
    key_.resize(head);
    return false;
  }

  void keepWhole(uint32_t ni) {
    const TNode& n = T_.nodes[ni];
    key_.push_back(ni);
    if (isPrimitive(n.kind)) return;
    key_.push_back(n.count);
    for (uint32_t k = 0; k < n.count; ++k) keepWhole(T_.kids[n.first + k]);
  }

  const Tape& T_;
  std::vector<uint32_t>& key_;
};

/// Appends the subtree of key[pos...] to T (children before parents, like compile()).
uint32_t decode(const Tape& base, std::span<const uint32_t> key, size_t& pos, Tape& T) {
  const uint32_t w = key[pos++];
  if (w == kPrunedEmpty) {
    TNode e;
    e.kind = NodeKind::Blend;  // no children, empty box: F = 0
    T.nodes.push_back(e);
    return uint32_t(T.nodes.size() - 1);
  }
  TNode n = base.nodes[w];
  n.bvh = -1;
  n.grid = -1;
  if (!isPrimitive(n.kind)) {
    const uint32_t count = key[pos++];
    std::vector<uint32_t> kids(count);
    for (uint32_t k = 0; k < count; ++k) kids[k] = decode(base, key, pos, T);
    n.first = uint32_t(T.kids.size());
    n.count = count;
    T.kids.insert(T.kids.end(), kids.begin(), kids.end());
  }
  T.nodes.push_back(n);
  return uint32_t(T.nodes.size() - 1);
}

}  // namespace

bool pruneKey(const Tape& T, const Box3& box, std::vector<uint32_t>& key) {
  if (T.empty) return false;
  bool nonNeg = true;
  return Pruner(T, key).visit(T.root, box, nonNeg);
}

std::shared_ptr<const Tape> buildPruned(const std::shared_ptr<const Tape>& base, std::span<const uint32_t> key) {
  auto T = std::make_shared<Tape>();
  T->base = base->base ? base->base : base;
  if (key.empty()) return T;
  size_t pos = 0;
  T->root = decode(*base, key, pos, *T);
  T->empty = false;
  T->minFeature = base->minFeature;
  T->minLimb = base->minLimb;
  return T;
}

}  // namespace sprig::blobtree::detail
