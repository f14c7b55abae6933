/// BlobTree evaluation benchmark: culled vs brute-force field evaluation, batched per-cell
/// evaluation, ray casting, and the cost of an n-ary blend at fixed local overlap.
///
/// Usage: bench_blobtree [--quick] | --image OUT.ppm
/// Prints throughputs and ratios against baselines computed in the same process.

#include "bench/bench_clock.h"
#include "bench/bench_scenes.h"
#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "core/parallel.h"
#include "core/rng.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

using namespace sprig;
using namespace sprig::blobtree;
using namespace sprig::bench;

namespace {

/// Runs f(i) for i in [0, n) on all threads; returns elapsed seconds.
template <class F>
double timedParallel(size_t n, F&& f) {
  auto t0 = Clock::now();
  parallelForRange(0, n, [&](size_t b, size_t e) {
    for (size_t i = b; i < e; ++i) f(i);
  }, 64);
  return seconds(t0);
}

/// Calls f(p) for the points p of the g x g x g lattice spanning box, x fastest.
template <class F>
void forEachLatticePoint(const Box3& box, int g, F&& f) {
  Vec3 step = box.size() / float(g - 1);
  for (int z = 0; z < g; ++z)
    for (int y = 0; y < g; ++y)
      for (int x = 0; x < g; ++x) f(box.lo + Vec3(float(x), float(y), float(z)) * step);
}

std::atomic<float> sink{0.0f};

/// The point sets a model is measured on: uniform points in its bounds (mostly empty space)
/// and points inside its surface cells (near the surface).
struct ModelPoints {
  CellSet cells;
  std::vector<Vec3> random, near;
};

/// Finds the surface cells of blob, prints their count and cost, and draws n random and n
/// near-surface points.
ModelPoints sampleModel(const CompiledBlob& blob, size_t n) {
  ModelPoints pts;
  Box3 box = blob.bounds();
  Rng rng(99);
  pts.random.resize(n);
  for (auto& p : pts.random) p = randomIn(rng, box.lo, box.hi);

  auto cs0 = Clock::now();
  float cell = 0.08f;
  pts.cells = blob.surfaceCells(cell);
  double cellS = seconds(cs0);
  const CellSet& cells = pts.cells;
  size_t primRefs = cells.primitives.size();
  std::fflush(stdout);
  std::printf("surface cells (%.3f): %zu cells in %.2f s, %.1f primitives per cell\n", double(cells.cellSize),
              cells.cells.size(), cellS, double(primRefs) / double(std::max<size_t>(1, cells.cells.size())));
  pts.near.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const Cell& c = cells.cells[rng.below(uint32_t(cells.cells.size()))];
    pts.near.push_back(randomIn(rng, c.box.lo, c.box.hi));
  }
  return pts;
}

/// Culled per-point evaluation, one thread (against brute force) then all threads.
void benchPerPoint(const CompiledBlob& blob, const ModelPoints& pts, int cones) {
  size_t nRandom = pts.random.size();
  const std::vector<Vec3>& random = pts.random;
  const std::vector<Vec3>& near = pts.near;
  {
    ThreadLimit one(1);
    double s = timedParallel(nRandom, [&](size_t i) { sink = sink + blob.value(random[i]); });
    double sn = timedParallel(nRandom, [&](size_t i) { sink = sink + blob.value(near[i]); });
    size_t nBrute = cones > 5000 ? 400 : 4000;
    double sb = timedParallel(nBrute, [&](size_t i) { sink = sink + blob.valueNoCulling(near[i]); });
    double culled = double(nRandom) / sn, brute = double(nBrute) / sb;
    std::printf("1 thread : random points %.2f M evals/s, near-surface %.2f M evals/s, brute force %.4f M evals/s "
                "-> culling speed-up x%.0f\n",
                double(nRandom) / s * 1e-6, culled * 1e-6, brute * 1e-6, culled / brute);
  }
  double s = timedParallel(nRandom, [&](size_t i) { sink = sink + blob.value(random[i]); });
  double sn = timedParallel(nRandom, [&](size_t i) { sink = sink + blob.value(near[i]); });
  std::printf("all threads: random points %.2f M evals/s, near-surface %.2f M evals/s\n", double(nRandom) / s * 1e-6,
              double(nRandom) / sn * 1e-6);
}

/// Per-cell batched mode: a 6x6x6 lattice in each surface cell (what a polygonizer or a
/// tile does), evaluated as one batch over the cell's short primitive list, against the same
/// lattice points evaluated one at a time.
void benchBatchedCells(const CompiledBlob& blob, const CellSet& cells, bool quick) {
  const int g = 6;
  size_t nc = std::min<size_t>(cells.cells.size(), quick ? 20000 : 200000);
  auto b0 = Clock::now();
  double bc0 = processCpuSeconds();
  parallelForRange(0, nc, [&](size_t b, size_t e) {
    std::vector<Vec3> pts(g * g * g);
    std::vector<float> out(pts.size());
    for (size_t ci = b; ci < e; ++ci) {
      const Cell& c = cells.cells[ci];
      size_t k = 0;
      forEachLatticePoint(c.box, g, [&](Vec3 p) { pts[k++] = p; });
      blob.valuesInCell(c, pts, out);
      sink = sink + out[0];
    }
  }, 16);
  double bs = seconds(b0), bcpu = processCpuSeconds() - bc0;
  size_t evals = nc * size_t(g * g * g);
  // Same lattice points one at a time, for the ratio.
  auto p0 = Clock::now();
  parallelForRange(0, nc, [&](size_t b, size_t e) {
    for (size_t ci = b; ci < e; ++ci) {
      float acc = 0.0f;
      forEachLatticePoint(cells.cells[ci].box, g, [&](Vec3 p) { acc += blob.value(p); });
      sink = sink + acc;
    }
  }, 16);
  double ps = seconds(p0);
  std::printf("all threads: per-cell batched %.1f M evals/s vs per-point on the same points %.1f M evals/s (x%.1f)\n",
              double(evals) / bs * 1e-6, double(evals) / ps * 1e-6, ps / bs);
  std::printf("  per-cell batched: %.1f M evals per CPU-second (x%d threads on idle cores: %.1f M evals/s)\n",
              double(evals) / bcpu * 1e-6, threadCount(), double(evals) / bcpu * 1e-6 * threadCount());
}

/// Ray casting with a pinhole camera looking at the model, against sphere tracing with the
/// global Lipschitz bound.
void benchRays(const CompiledBlob& blob, bool quick) {
  Box3 box = blob.bounds();
  int w = quick ? 96 : 256, h = w;
  Vec3 center = box.center();
  float radius = 0.5f * glm::length(box.size());
  Vec3 eye = center + Vec3(0.3f, 0.2f, 1.0f) * (2.2f * radius);
  Vec3 fwd = glm::normalize(center - eye), right = glm::normalize(glm::cross(fwd, Vec3(0, 1, 0)));
  Vec3 up = glm::cross(right, fwd);
  auto rayOf = [&](size_t i) {
    float u = (float(i % size_t(w)) + 0.5f) / float(w) * 2.0f - 1.0f;
    float v = (float(i / size_t(w)) + 0.5f) / float(h) * 2.0f - 1.0f;
    return Ray{eye, fwd + 0.45f * (u * right + v * up)};
  };
  std::atomic<int> hits{0};
  double rs = timedParallel(size_t(w * h), [&](size_t i) {
    if (blob.intersect(rayOf(i), 0.0f, 1e30f)) hits++;
  });
  std::printf("all threads: %d rays, %d hits, %.3f M rays/s (intersect: segment tracing, local Lipschitz)\n", w * h,
              hits.load(), double(w * h) / rs * 1e-6);
  // Baseline: sphere tracing with the global Lipschitz bound (culled evaluation, else a
  // single ray would take minutes): isolates the gain of local bounds and interval skipping.
  size_t nb = 8;
  double gL = blob.lipschitz();
  std::atomic<long> steps{0};
  auto g0 = Clock::now();
  parallelFor(0, nb, [&](size_t k) {
    size_t i = size_t(w * h / 2 + w / 2) + k * 3;
    Ray r = rayOf(i);
    Vec3 d = glm::normalize(r.direction);
    float tt = 0.0f;
    long it = 0;
    for (; it < 20000000 && tt < 4.0f * radius; ++it) {
      float f = blob.value(r.origin + tt * d);
      if (f >= kIso) break;
      tt += std::max(float((kIso - f) / gL), 1e-6f);
    }
    steps += it;
    sink = sink + tt;
  });
  double bsec = seconds(g0);
  std::printf("baseline: global-Lipschitz (%.0f) sphere tracing %.6f M rays/s (%.0f steps/ray) -> local bounds x%.0f\n",
              gL, double(nb) / bsec * 1e-6, double(steps.load()) / double(nb), (double(w * h) / rs) / (double(nb) / bsec));
}

/// Measures a branching model of the given number of cones: surface cells, per-point and
/// per-cell evaluation, and ray casting.
void benchModel(int cones, bool quick) {
  BlobTree t;
  double compileS = 0;
  CompiledBlob blob = timedCompile(t, branching(t, cones, 1234), compileS);
  Box3 box = blob.bounds();
  std::printf("\n== %d cones: bounds (%.1f %.1f %.1f) .. (%.1f %.1f %.1f), compile %.1f ms, %d threads\n", cones,
              double(box.lo.x), double(box.lo.y), double(box.lo.z), double(box.hi.x), double(box.hi.y),
              double(box.hi.z), compileS * 1e3, threadCount());
  ModelPoints pts = sampleModel(blob, quick ? 200000 : 2000000);
  benchPerPoint(blob, pts, cones);
  benchBatchedCells(blob, pts.cells, quick);
  benchRays(blob, quick);
}

/// A planar grid of parallel cones with fixed spacing: local overlap does not depend on n.
void benchOverlap(int n) {
  BlobTree t;
  std::vector<NodeId> kids;
  int side = int(std::ceil(std::sqrt(double(n))));
  for (int i = 0; i < n; ++i) {
    float x = float(i % side) * 0.6f, z = float(i / side) * 0.6f;
    kids.push_back(t.cone(Vec3(x, 0, z), Vec3(x + 0.3f, 2, z), 0.25f, 0.2f));
  }
  CompiledBlob b = compile(t, t.blend(kids));
  Box3 box = b.bounds();
  Rng rng(7);
  const size_t m = 1000000;
  std::vector<Vec3> pts(m);
  for (auto& p : pts) p = randomIn(rng, box.lo, box.hi);
  ThreadLimit one(1);
  auto t0 = Clock::now();
  float acc = 0.0f;
  for (const Vec3& p : pts) acc += b.value(p);
  double s = seconds(t0);
  sink = sink + acc;
  std::printf("n-ary blend of %5d cones (same local overlap): %.1f ns per point (1 thread)\n", n, s / double(m) * 1e9);
}

/// Renders a small demo scene (branching cones, PCM pair, torus, bent segment, CSG cut)
/// with intersect() and writes a binary PPM: a visual check of hits and normals.
void renderImage(const char* path) {
  BlobTree t;
  std::vector<NodeId> kids;
  Rng rng(5);
  struct Tip { Vec3 p, dir; float r; };
  std::vector<Tip> tips{{Vec3(0, -2, 0), Vec3(0, 1, 0), 0.3f}};
  for (int i = 0; i < 40; ++i) {
    Tip b = tips[rng.below(uint32_t(tips.size()))];
    Vec3 dir = glm::normalize(b.dir + randomIn(rng, Vec3(-0.6f), Vec3(0.6f)));
    float r1 = std::max(0.03f, b.r * 0.8f);
    Vec3 end = b.p + float(rng.uniform(0.5, 1.0)) * dir;
    TextureAttr tex;
    tex.textureId = uint16_t(i % 3);
    kids.push_back(t.cone(b.p, end, b.r, r1, tex));
    tips.push_back({end, dir, r1});
  }
  NodeId tree = t.blend(kids);
  NodeId pcm = t.pcm(t.point(Vec3(2.2f, -1.2f, 0), 0.6f), t.point(Vec3(2.9f, -1.2f, 0), 0.5f));
  NodeId ring = t.translate(t.rotate(t.torus(Vec3(0), Vec3(0, 1, 0), 0.7f, 0.15f), Vec3(1, 0, 0), 1.0f), Vec3(-2.3f, -1.0f, 0));
  NodeId bent = t.bend(t.segment(Vec3(-2.8f, 1.0f, 0), Vec3(-1.2f, 1.0f, 0), 0.15f), Vec3(-2.8f, 1.0f, 0),
                       Vec3(-1.2f, 1.0f, 0), 0.5f, Vec3(0, 1, 0));
  NodeId all = t.blend(std::vector<NodeId>{tree, pcm, ring, bent});
  NodeId cut = t.difference(all, t.halfspace(Vec3(0, 0, 0.25f), Vec3(0, 0, -1), 0.01f));
  CompiledBlob blob = compile(t, cut);
  const int w = 320, h = 320;
  std::vector<unsigned char> img(size_t(w * h * 3));
  Vec3 eye(0.5f, 0.5f, 9.0f);
  parallelFor(0, size_t(h), [&](size_t y) {
    for (int x = 0; x < w; ++x) {
      Vec3 dir(float(x - w / 2) / float(w) * 0.8f, -float(int(y) - h / 2) / float(h) * 0.8f, -1.0f);
      auto hit = blob.intersect(Ray{eye, dir}, 0.0f, 100.0f);
      Vec3 c(0.15f, 0.17f, 0.2f);
      if (hit) {
        float l = std::max(0.0f, glm::dot(hit->normal, glm::normalize(Vec3(0.5f, 0.8f, 0.6f))));
        static const Vec3 pal[3] = {Vec3(0.8f, 0.55f, 0.35f), Vec3(0.45f, 0.7f, 0.4f), Vec3(0.4f, 0.55f, 0.85f)};
        Vec3 base(0.0f);
        for (int k = 0; k < hit->attributes.textureCount; ++k)
          base += hit->attributes.textureWeights[size_t(k)] * pal[hit->attributes.textureIds[size_t(k)] % 3];
        if (hit->attributes.textureCount == 0) base = Vec3(0.7f);
        float stripe = 0.85f + 0.15f * std::sin(hit->attributes.uv.y * 12.0f);
        c = base * (0.2f + 0.8f * l) * stripe;
      }
      for (int k = 0; k < 3; ++k)
        img[(y * size_t(w) + size_t(x)) * 3 + size_t(k)] = (unsigned char)(std::clamp(c[k], 0.0f, 1.0f) * 255.0f);
    }
  });
  FILE* f = std::fopen(path, "wb");
  if (!f) return;
  std::fprintf(f, "P6\n%d %d\n255\n", w, h);
  std::fwrite(img.data(), 1, img.size(), f);
  std::fclose(f);
  std::printf("wrote %s\n", path);
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  if (argc > 2 && std::strcmp(argv[1], "--image") == 0) {
    renderImage(argv[2]);
    return 0;
  }
  std::printf("bench_blobtree: %s\n", quick ? "quick" : "full");
  benchOverlap(100);
  benchOverlap(10000);
  benchModel(2000, quick);
  benchModel(20000, quick);
  std::printf("(sink %g)\n", double(sink.load()));
  return 0;
}
