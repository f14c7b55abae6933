#include "blobtree/detail/accel.h"

#include "blobtree/detail/tape.h"

#include <algorithm>
#include <numeric>

namespace sprig::blobtree::detail {

// ---- BVH -------------------------------------------------------------------------------

namespace {
constexpr uint32_t kBvhLeaf = 4;

void buildRec(Tape& tape, uint32_t nodeIndex, std::vector<uint32_t>& order, uint32_t begin, uint32_t end,
              const std::vector<Box3>& boxes, const std::vector<Vec3>& centers) {
  Box3 b, cb;
  for (uint32_t i = begin; i < end; ++i) {
    b.extend(boxes[order[i]]);
    cb.extend(centers[order[i]]);
  }
  tape.bvh[nodeIndex].box = b;
  if (end - begin <= kBvhLeaf) {
    tape.bvh[nodeIndex].first = uint32_t(tape.bvhItems.size());
    tape.bvh[nodeIndex].count = end - begin;
    for (uint32_t i = begin; i < end; ++i) tape.bvhItems.push_back(order[i]);
    return;
  }
  Vec3 ext = cb.size();
  int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  uint32_t mid = (begin + end) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](uint32_t a, uint32_t c) { return centers[a][axis] < centers[c][axis]; });
  uint32_t left = uint32_t(tape.bvh.size());
  tape.bvh.emplace_back();
  tape.bvh.emplace_back();
  tape.bvh[nodeIndex].first = left;
  tape.bvh[nodeIndex].count = 0;
  buildRec(tape, left, order, begin, mid, boxes, centers);
  buildRec(tape, left + 1, order, mid, end, boxes, centers);
}
}  // namespace

int32_t buildBvh(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items) {
  std::vector<uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::vector<Vec3> centers(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    // Unbounded boxes (cutters) sort by the origin.
    centers[i] = isHuge(boxes[i]) || boxes[i].empty() ? Vec3(0.0f) : boxes[i].center();
  }
  int32_t root = int32_t(tape.bvh.size());
  tape.bvh.emplace_back();
  size_t firstItem = tape.bvhItems.size();
  buildRec(tape, uint32_t(root), order, 0, uint32_t(boxes.size()), boxes, centers);
  // Map local indices to the caller's items.
  for (size_t i = firstItem; i < tape.bvhItems.size(); ++i) tape.bvhItems[i] = items[tape.bvhItems[i]];
  return root;
}

int32_t buildGrid(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items) {
  PointGrid g;
  std::vector<float> ext;
  Box3 all;
  for (const Box3& b : boxes) {
    if (b.empty() || isHuge(b)) continue;
    Vec3 e = b.size();
    ext.push_back(std::max(e.x, std::max(e.y, e.z)));
    all.extend(b);
  }
  if (ext.empty()) return -1;
  std::nth_element(ext.begin(), ext.begin() + long(ext.size() / 2), ext.end());
  // Half the median child extent: a child spans 2-4 cells per axis, a cell lists few children.
  float cell = std::max(0.5f * ext[ext.size() / 2], 1e-6f);
  // Keep the grid's key range within 21 bits per axis.
  Vec3 span = all.size();
  cell = std::max(cell, std::max(span.x, std::max(span.y, span.z)) / float(1 << 19));
  g.origin = all.lo;
  g.bounds = all;
  g.invCell = 1.0f / cell;
  std::vector<std::pair<uint64_t, uint32_t>> pairs;
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box3& b = boxes[i];
    if (b.empty()) continue;
    if (isHuge(b)) {
      g.always.push_back(items[i]);
      continue;
    }
    glm::ivec3 lo = glm::ivec3(glm::floor((b.lo - g.origin) * g.invCell));
    glm::ivec3 hi = glm::ivec3(glm::floor((b.hi - g.origin) * g.invCell));
    glm::ivec3 n = hi - lo + 1;
    if (int64_t(n.x) * n.y * n.z > 512) {
      g.always.push_back(items[i]);
      continue;
    }
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) pairs.push_back({cellKey(x, y, z), items[i]});
  }
  std::sort(pairs.begin(), pairs.end());
  size_t unique = 0;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (i == 0 || pairs[i].first != pairs[i - 1].first) ++unique;
  uint32_t cap = 16;
  while (cap < 2 * unique) cap *= 2;
  g.mask = cap - 1;
  g.tableKey.assign(cap, PointGrid::kEmptyKey);
  g.tableFirst.assign(cap, 0);
  g.tableCount.assign(cap, 0);
  for (size_t i = 0; i < pairs.size();) {
    size_t j = i;
    while (j < pairs.size() && pairs[j].first == pairs[i].first) ++j;
    uint32_t slot = hashKey(pairs[i].first) & g.mask;
    while (g.tableKey[slot] != PointGrid::kEmptyKey) slot = (slot + 1) & g.mask;
    g.tableKey[slot] = pairs[i].first;
    g.tableFirst[slot] = uint32_t(g.items.size());
    g.tableCount[slot] = uint32_t(j - i);
    for (size_t k = i; k < j; ++k) g.items.push_back(pairs[k].second);
    i = j;
  }
  tape.grids.push_back(std::move(g));
  return int32_t(tape.grids.size() - 1);
}

}  // namespace sprig::blobtree::detail
