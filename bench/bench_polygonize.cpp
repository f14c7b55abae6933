/// Polygonization benchmark: sparse near-surface polygonization of a synthetic branching
/// structure of 2,000 cones, against a dense-grid baseline computed in the same run.
///
/// Usage: bench_polygonize [--quick] [--cones N] [--no-baseline] [--cell H] [--dual | --tets] [--blend]
/// (--cell replaces the target cell, half the smallest radius; --dual runs only the dual
/// mesher with batched Newton steps, the default, and no baseline; --tets only marching
/// tetrahedra, without the dense baseline; --blend keeps every
/// vertex's blended attributes as painting callers do, PolygonizeOptions::VertexData::Blend,
/// where the default keeps its uv.)
/// Each mesh's bytes (positions, normals, uvs, triangles) are printed as an FNV-1a hash.
/// Prints time, triangles/s, cells and field evaluations; the ratio compares the sparse
/// polygonizer with sampling every grid point of the bounds (the least any dense-grid
/// mesher must do) at the same cell size.

#include "bench/bench_clock.h"
#include "bench/bench_scenes.h"
#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/parallel.h"
#include "core/rng.h"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

using namespace sprig;
using namespace sprig::blobtree;
using namespace sprig::bench;

namespace {

std::atomic<size_t> sink{0};

/// FNV-1a over the bytes of a vector, continuing from h.
template <class T>
uint64_t fnv(uint64_t h, const std::vector<T>& v) {
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  for (size_t i = 0; i < v.size() * sizeof(T); ++i) h = (h ^ p[i]) * 0x100000001b3ULL;
  return h;
}

/// A hash of the mesh's bytes: the same hash means the same positions, normals, uvs and
/// triangles in the same order.
uint64_t meshHash(const Mesh& m) {
  uint64_t h = 0xcbf29ce484222325ULL;
  h = fnv(h, m.positions);
  h = fnv(h, m.normals);
  h = fnv(h, m.uvs);
  return fnv(h, m.triangles);
}

/// Samples every grid point of blob's bounds at cell size h, one batched values() call per
/// grid row, in parallel over slabs; returns seconds and sets points.
double denseSampling(const CompiledBlob& blob, float h, size_t& points, double& cpu, int slabStride = 1) {
  Box3 b = blob.bounds();
  glm::ivec3 n = glm::ivec3(glm::ceil((b.hi - b.lo) / h)) + 1;
  points = size_t(n.x) * size_t(n.y) * size_t(n.z);
  auto t0 = Clock::now();
  double c0 = processCpuSeconds();
  size_t slabs = (size_t(n.z) + size_t(slabStride) - 1) / size_t(slabStride);
  parallelFor(0, slabs, [&](size_t zi) {
    size_t z = zi * size_t(slabStride);
    std::vector<Vec3> row(size_t(n.x));
    std::vector<float> out(size_t(n.x));
    size_t inside = 0;
    for (int y = 0; y < n.y; ++y) {
      for (int x = 0; x < n.x; ++x) row[size_t(x)] = b.lo + h * Vec3(float(x), float(y), float(z));
      blob.values(row, out);
      for (float v : out) inside += v > kIso;
    }
    sink += inside;
  });
  double scale = double(n.z) / double(slabs);  // extrapolated to every slab
  cpu = (processCpuSeconds() - c0) * scale;
  return seconds(t0) * scale;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, baseline = true, dualOnly = false, tetsOnly = false, blend = false;
  int cones = 2000;
  float cellOverride = 0.0f;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--no-baseline")) baseline = false;
    else if (!std::strcmp(argv[i], "--dual")) dualOnly = true, baseline = false;
    else if (!std::strcmp(argv[i], "--tets")) tetsOnly = true, baseline = false;
    else if (!std::strcmp(argv[i], "--blend")) blend = true;
    else if (!std::strcmp(argv[i], "--cell") && i + 1 < argc) cellOverride = float(std::atof(argv[++i]));
    else if (!std::strcmp(argv[i], "--cones") && i + 1 < argc) cones = std::atoi(argv[++i]);
  }
  if (quick) cones = std::min(cones, 300);

  BlobTree tree;
  double compileS = 0;
  CompiledBlob blob = timedCompile(tree, branching(tree, cones, 1234), compileS);
  Box3 b = blob.bounds();
  float rMin = blob.smallestFeature();
  std::printf("== %d cones, bounds (%.1f %.1f %.1f) .. (%.1f %.1f %.1f), smallest radius %.3f, compile %.1f ms, %d threads\n",
              cones, b.lo.x, b.lo.y, b.lo.z, b.hi.x, b.hi.y, b.hi.z, rMin, compileS * 1e3, threadCount());

  // 1. Target: cells half the smallest radius (the automatic default), by marching
  // tetrahedra (the reference) and by dual marching cubes, in this order.
  double tetSeconds = 0;
  size_t tetTriangles = 0;
  // The dual mesher twice: its Newton steps through scalar sample() calls (the baseline),
  // then batched (PolygonizeOptions::batchedNewton, the default).
  struct Run {
    PolygonizeOptions::Mesher mesher;
    bool batched;
    const char* name;
  };
  double dualScalarCpu = 0;
  for (const Run& run : {Run{PolygonizeOptions::Mesher::MarchingTetrahedra, false, "marching tetrahedra"},
                         Run{PolygonizeOptions::Mesher::DualMarchingCubes, false, "dual marching cubes, scalar Newton"},
                         Run{PolygonizeOptions::Mesher::DualMarchingCubes, true, "dual marching cubes, batched Newton"}}) {
    const auto mesher = run.mesher;
    const bool dual = mesher == PolygonizeOptions::Mesher::DualMarchingCubes;
    if ((dualOnly && !(dual && run.batched)) || (tetsOnly && dual)) continue;
    PolygonizeOptions opt;
    opt.mesher = mesher;
    opt.batchedNewton = run.batched;
    if (blend) opt.vertexData = PolygonizeOptions::VertexData::Blend;
    opt.cellSize = cellOverride > 0.0f ? cellOverride : 0.5f * rMin;
    auto t0 = Clock::now();
    double c0 = processCpuSeconds();
    PolygonizeResult r = polygonizeDetailed(blob, opt);
    double s = seconds(t0), cpu = processCpuSeconds() - c0;
    MeshTopology topo = analyzeTopology(r.mesh);
    std::printf("sparse %s%s, cell %.4f (requested %.4f): %.2f s wall, %.2f s CPU, %zu triangles (%.2f M triangles/s wall, "
                "%.2f M per CPU second), %zu vertices\n",
                run.name, blend ? " with blended attributes" : "", r.cellSize, opt.cellSize, s, cpu,
                r.mesh.triangleCount(), r.mesh.triangleCount() / s * 1e-6, r.mesh.triangleCount() / cpu * 1e-6,
                r.mesh.vertexCount());
    std::printf("  %zu surface cells, %zu with a sign change, %zu grid samples, %zu field evaluations (%.1f M/s); "
                "closed %s, manifold %s\n",
                r.surfaceCells, r.activeCells, r.gridSamples, r.fieldEvaluations, r.fieldEvaluations / s * 1e-6,
                topo.closed() ? "yes" : "NO", topo.manifold() ? "yes" : "NO");
    std::printf("  phases (wall): surface cells %.2f s, grid samples %.2f s, triangulation %.2f s, vertices %.2f s\n",
                r.cellSeconds, r.sampleSeconds, r.triangulateSeconds, r.vertexSeconds);
    std::printf("  phases (CPU):  surface cells %.2f s, grid samples %.2f s, triangulation %.2f s, vertices %.2f s\n",
                r.cellCpuSeconds, r.sampleCpuSeconds, r.triangulateCpuSeconds, r.vertexCpuSeconds);
    std::printf("  mesh hash %016llx\n", (unsigned long long)meshHash(r.mesh));
    if (dual) {
      if (dualOnly) continue;
      std::printf("  dual / tetrahedra: %.2fx the time, %.2fx the triangles\n", s / tetSeconds,
                  double(r.mesh.triangleCount()) / double(tetTriangles));
      if (!run.batched) dualScalarCpu = cpu;
      else std::printf("  batched / scalar Newton: %.2fx the CPU time\n", cpu / dualScalarCpu);
      continue;
    }
    tetSeconds = s;
    tetTriangles = r.mesh.triangleCount();
    // The dense baseline at the same cell, from every 16th slab (extrapolated).
    if (!baseline) continue;
    size_t points = 0;
    double denseCpu = 0;
    double dense = denseSampling(blob, r.cellSize, points, denseCpu, quick ? 4 : 16);
    std::printf("  dense grid sampling at this cell (extrapolated from a subset of slabs): %.1f s wall, %.1f s CPU, "
                "%.0f M points; dense / sparse = %.1fx wall, %.1fx CPU\n",
                dense, denseCpu, points * 1e-6, dense / s, denseCpu / cpu);
  }
  if (!baseline) return 0;

  // 2. Sparse vs dense at a coarser cell the dense grid can afford.
  {
    PolygonizeOptions opt;
    opt.cellSize = quick ? 4.0f * rMin : 2.0f * rMin;
    auto t0 = Clock::now();
    double c0 = processCpuSeconds();
    PolygonizeResult r = polygonizeDetailed(blob, opt);
    double sparse = seconds(t0), sparseCpu = processCpuSeconds() - c0;
    size_t points = 0;
    double denseCpu = 0;
    double dense = denseSampling(blob, r.cellSize, points, denseCpu);
    std::printf("cell %.4f: sparse polygonization %.3f s wall / %.3f s CPU (%zu grid samples, %zu triangles); "
                "dense grid sampling %.3f s wall / %.3f s CPU (%zu points); dense / sparse = %.1fx wall, %.1fx CPU\n",
                r.cellSize, sparse, sparseCpu, r.gridSamples, r.mesh.triangleCount(), dense, denseCpu, points,
                dense / sparse, denseCpu / sparseCpu);
  }
  return sink.load() == size_t(-1) ? 1 : 0;
}
