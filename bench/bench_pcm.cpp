/// PCM combination micro-benchmark: the cost per point and child of the batch evaluator's
/// PCM node step (blobtree/detail/batch_eval.cpp) with the current combination (PcmAccum:
/// the two strongest children, only the deepest compression) against the formula it
/// replaced (F = f_max + Σ_{j≠max} d(f_j)), both in this process over the same child values.
///
/// Usage: bench_pcm [--children K] [--rounds R]
/// The child values are those a tracer batch near a junction sees: per point, each child
/// is 0 (outside its support) with probability 1/2, else uniform in [0, 1] (a third of
/// those in the contact band [c − w, c]).

#include "bench/bench_clock.h"
#include "blobtree/detail/pcm.h"
#include "core/rng.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

using namespace sprig;
using namespace sprig::blobtree;
using namespace sprig::blobtree::detail;
using namespace sprig::bench;

namespace {

constexpr int kBlock = 256;  // batch_eval's block

float sink = 0.0f;

/// The step before PcmAccum (commit d981e3a's parent): summed deformations, the strongest's removed.
void oldPcm(const PcmDerived& pp, const float* child, int kids, int n, float* out) {
  alignas(32) float dsum[kBlock], dmax[kBlock];
  std::fill(out, out + n, 0.0f);
  std::fill(dsum, dsum + n, 0.0f);
  std::fill(dmax, dmax + n, 0.0f);
  for (int c = 0; c < kids; ++c) {
    const float* tmp = child + size_t(c) * kBlock;
    for (int i = 0; i < n; ++i) {
      float f = std::max(0.0f, tmp[i]);
      float d = pcmD(pp, f, nullptr);
      dsum[i] += d;
      if (f > out[i]) { out[i] = f; dmax[i] = d; }
    }
  }
  for (int i = 0; i < n; ++i) out[i] = out[i] > 0.0f ? std::max(0.0f, out[i] + dsum[i] - dmax[i]) : 0.0f;
}

/// The current step (batch_eval.cpp, NodeKind::Pcm), verbatim.
void newPcm(const PcmDerived& pp, const float* child, int kids, int n, float* out) {
  alignas(32) float d1[kBlock], f2[kBlock], d2[kBlock], bulge[kBlock];
  std::fill(out, out + n, 0.0f);
  std::fill(d1, d1 + n, 0.0f);
  std::fill(f2, f2 + n, 0.0f);
  std::fill(d2, d2 + n, 0.0f);
  std::fill(bulge, bulge + n, 0.0f);
  for (int c = 0; c < kids; ++c) {
    const float* tmp = child + size_t(c) * kBlock;
    for (int i = 0; i < n; ++i) {
      float f = std::max(0.0f, tmp[i]);
      float d = pcmD(pp, f, nullptr);
      bulge[i] += std::max(0.0f, d);
      if (f > out[i]) {
        f2[i] = out[i];
        d2[i] = d1[i];
        out[i] = f;
        d1[i] = d;
      } else if (f > f2[i]) {
        f2[i] = f;
        d2[i] = d;
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    const PcmAccum acc{out[i], d1[i], f2[i], d2[i], bulge[i]};
    out[i] = acc.value();
  }
}

}  // namespace

int main(int argc, char** argv) {
  int rounds = 20000;
  std::vector<int> kidCounts{2, 3, 5};
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--children") && i + 1 < argc) kidCounts = {std::atoi(argv[++i])};
  }
  const PcmDerived pp = derivePcm(PcmParams{});
  Rng rng(19);
  std::printf("PCM node step of the batch evaluator, %d-point batches, %d rounds; CPU ns per point and child "
              "(best of 5 alternating runs)\n", kBlock, rounds);
  for (int kids : kidCounts) {
    // 64 different batches of child values, cycled, so the branches are not learnt.
    constexpr int kSets = 64;
    std::vector<float> child(size_t(kSets) * size_t(kids) * kBlock);
    for (float& f : child) f = rng.uniform(0.0, 1.0) < 0.5 ? 0.0f : float(rng.uniform(0.0, 1.0));
    alignas(32) float out[kBlock];
    double best[2] = {1e30, 1e30};
    for (int rep = 0; rep < 5; ++rep)
      for (int which = 0; which < 2; ++which) {
        double c0 = threadCpuSeconds();
        for (int r = 0; r < rounds; ++r) {
          const float* set = child.data() + size_t(r % kSets) * size_t(kids) * kBlock;
          if (which == 0) oldPcm(pp, set, kids, kBlock, out);
          else newPcm(pp, set, kids, kBlock, out);
          sink += out[r % kBlock];
        }
        best[which] = std::min(best[which], threadCpuSeconds() - c0);
      }
    const double per = 1e9 / (double(rounds) * kBlock * kids);
    std::printf("%d children: before (summed deformations) %.2f ns, PcmAccum %.2f ns: %.2fx the cost\n", kids,
                best[0] * per, best[1] * per, best[1] / best[0]);
  }
  return sink == -1.0f ? 1 : 0;
}
