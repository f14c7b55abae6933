#pragma once
/// Synthetic BlobTree scenes shared by the benchmarks.

#include "bench/bench_clock.h"
#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "core/rng.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace sprig::bench {

/// A uniformly random point in the box lo..hi.
inline Vec3 randomIn(Rng& rng, Vec3 lo, Vec3 hi) {
  return Vec3(float(rng.uniform(lo.x, hi.x)), float(rng.uniform(lo.y, hi.y)), float(rng.uniform(lo.z, hi.z)));
}

/// A synthetic branching structure of n cones: each cone starts at the tip of a random
/// recent earlier cone (one of the last 40, so it spreads out like a tree rather than a
/// ball); radii shrink by 0.93 per cone down to 0.04. About 2 cones per unit volume overlap.
inline blobtree::NodeId branching(blobtree::BlobTree& t, int n, uint64_t seed) {
  Rng rng(seed);
  struct Tip {
    Vec3 p, dir;
    float r;
  };
  std::vector<Tip> tips{{Vec3(0), Vec3(0, 1, 0), 0.35f}};
  std::vector<blobtree::NodeId> kids;
  for (int i = 0; i < n; ++i) {
    uint32_t k = uint32_t(tips.size()) - 1 - rng.below(std::min<uint32_t>(uint32_t(tips.size()), 40));
    Tip base = tips[k];
    Vec3 dir = glm::normalize(base.dir + randomIn(rng, Vec3(-0.7f), Vec3(0.7f)));
    float len = float(rng.uniform(0.7, 1.3));
    float r1 = std::max(0.04f, base.r * 0.93f);
    Vec3 end = base.p + len * dir;
    kids.push_back(t.cone(base.p, end, base.r, r1));
    tips.push_back({end, dir, r1});
  }
  return t.blend(kids);
}

/// compile(t, root), with the wall seconds it took in compileSeconds.
inline blobtree::CompiledBlob timedCompile(const blobtree::BlobTree& t, blobtree::NodeId root, double& compileSeconds) {
  auto t0 = Clock::now();
  blobtree::CompiledBlob blob = blobtree::compile(t, root);
  compileSeconds = seconds(t0);
  return blob;
}

}  // namespace sprig::bench
