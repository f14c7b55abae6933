// Benchmark of BlobTree trees ("BlobTree Trees", Galbraith, MacMurchy, Wyvill): the poplar of
// grammars/tree_poplar.lsys with PCM junctions, grown to >= 2,000 internodes.
//
// Prints: derivation + turtle time, BlobTree build time, compile time, exact render time
// (Embree user geometry over surface cells, default 1536x2048 at 9 samples per pixel, the
// paper's Fig. 17-18 setting), and polygonization time; wall time and process CPU time
// (all threads: on a shared machine CPU/2 estimates an idle 2-core wall time). Baselines in
// the same process: field evaluations per second with culling (compiled tape + BVH) against
// the brute-force evaluator that visits every primitive, and the exact render's rays/s
// against the reference per-cell tracer (ImplicitOptions::batched = false) on a 1/6-size
// image at 1 spp.
//
// Usage: bench_tree [steps=11] [width=1536] [height=2048] [spp=9] [out.png] [cell=0] [bend=8] [full=0]
//   full: 1 also renders the exact image with every cell tracing the whole tape
//   (ImplicitOptions::prunedTapes = false), the baseline of the per-cell pruned tapes, and
//   writes it beside out.png as out.png.full.png
//   cell: surface cell edge of the exact render in world units (0 = the renderer's
//   automatic size); bend: the bend angle of order-1 laterals in degrees (0 = no bends);
//   polygonization uses cells of 1/400 of the bounds diagonal
//   (run from the repository root; width 0 skips the render; out "-" writes no image)

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_view.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/atomic_file.h"
#include "core/image.h"
#include "core/rng.h"
#include "core/timer.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "organisms/tree_builder.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "textures/procedural.h"

using namespace sprig;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

/// The command line (see the file comment).
struct Args {
  int steps = 11, width = 1536, height = 2048, spp = 9;
  std::string out;
  float cell = 0.0f;
  double bendDeg = 8.0;
  bool fullTape = false;
};

Args parseArgs(int argc, char** argv) {
  Args a;
  if (argc > 1) a.steps = std::atoi(argv[1]);
  if (argc > 2) a.width = std::atoi(argv[2]);
  if (argc > 3) a.height = std::atoi(argv[3]);
  if (argc > 4) a.spp = std::atoi(argv[4]);
  if (argc > 5 && std::string(argv[5]) != "-") a.out = argv[5];
  if (argc > 6) a.cell = float(std::atof(argv[6]));
  if (argc > 7) a.bendDeg = std::atof(argv[7]);
  a.fullTape = argc > 8 && std::atoi(argv[8]) != 0;
  return a;
}

/// The poplar of grammars/tree_poplar.lsys grown for `steps` steps (derivation and turtle).
lsystem::Skeleton growPoplar(int steps) {
  const std::string text = readFile("grammars/tree_poplar.lsys");
  lsystem::GrammarOverrides ov;
  ov.derivationLength = steps;
  const lsystem::Grammar grammar = lsystem::parseGrammar(text, "grammars/tree_poplar.lsys", ov);
  lsystem::Deriver deriver(grammar);
  const lsystem::ModuleString& modules = deriver.derive();
  lsystem::TurtleSettings ts;
  ts.widthScale = 0.02;
  ts.tropism = DVec3(0, 1, 0);
  ts.elasticity = 0.04;
  return lsystem::interpret(deriver.interpret(modules), deriver.symbols(), ts);
}

/// Baseline: culled field evaluation against visiting every primitive, same points.
void benchCulling(const blobtree::CompiledBlob& compiled) {
  const Box3 b = compiled.bounds();
  std::vector<Vec3> pts(20000);
  Rng rng(7);
  for (auto& p : pts) p = b.lo + Vec3(float(rng.uniform()), float(rng.uniform()), float(rng.uniform())) * b.size();
  double sink = 0;
  auto t = Clock::now();
  for (const auto& p : pts) sink += compiled.value(p);
  const double culledS = since(t);
  const size_t bruteN = 2000;
  t = Clock::now();
  for (size_t i = 0; i < bruteN; ++i) sink -= compiled.valueNoCulling(pts[i]);
  const double bruteS = since(t);
  const double culledRate = pts.size() / culledS, bruteRate = bruteN / bruteS;
  std::printf("field evaluations: culled %.3g /s, brute force %.3g /s, ratio %.1fx (checksum %.3g)\n", culledRate,
              bruteRate, culledRate / bruteRate, sink);
}

/// A scene with the bark texture and the wood material (id 0) and compiled under io, for
/// a.spp samples of a.width x a.height through camera; returns the surface cells' wall and
/// CPU seconds.
std::pair<double, double> woodScene(render::Scene& scene, const blobtree::CompiledBlob& compiled, const render::ImplicitOptions& io,
                                    const render::Camera& camera, const Args& a) {
  scene.setExpectedSamples(camera, a.width, a.height, a.spp);
  auto bark = std::make_shared<textures::BarkTexture>(textures::BarkOptions{});
  scene.addTexture([bark](Vec2 uv, const Vec3&) { return bark->color(uv); });
  const uint32_t wood = scene.addMaterial(render::Material{Vec3(0.62f, 0.60f, 0.52f), 0.7f, 0.03f, 0});
  const auto t = Clock::now();
  const double c0 = processCpuSeconds();
  scene.addImplicit(compiled, wood, io);
  scene.commit();
  return {since(t), processCpuSeconds() - c0};
}

/// Renders scene; returns the image and the render's wall and CPU seconds.
Image timedRender(const render::Scene& scene, const render::Camera& camera, const render::RenderSettings& rs,
                  render::RenderStats& stats, double& wallS, double& cpuS) {
  const auto t = Clock::now();
  const double c0 = processCpuSeconds();
  Image image = render::renderImage(scene, camera, rs, &stats);
  wallS = since(t);
  cpuS = processCpuSeconds() - c0;
  return image;
}

/// The exact render, then its baselines: every cell tracing the whole tape (a.fullTape),
/// and the reference per-cell tracer on a 1/6-size image at 1 spp.
void benchExactRender(const blobtree::CompiledBlob& compiled, const Args& a) {
  render::ImplicitOptions io;
  io.cellSize = a.cell;
  render::Scene scene;
  const render::Camera camera = bench::benchCamera(compiled.bounds(), 20, 8, a.width, a.height);
  const auto [sceneS, sceneCpu] = woodScene(scene, compiled, io, camera, a);
  render::RenderSettings rs = bench::benchSettings(a.width, a.height, a.spp);
  render::RenderStats stats;
  double renderS = 0, renderCpu = 0;
  Image image = timedRender(scene, camera, rs, stats, renderS, renderCpu);
  std::printf("exact render %dx%d, %d spp: surface cells %.2f s (CPU %.2f s), %zu cells (%zu free); render %.2f s "
              "(CPU %.2f s), %.3g rays (%.3g camera), %.3g rays/s, %.3g rays per CPU s\n",
              a.width, a.height, a.spp, sceneS, sceneCpu, scene.stats().implicitCells, scene.stats().implicitFreeCells,
              renderS, renderCpu,
              double(stats.rays()), double(stats.cameraRays), stats.raysPerSecond(), double(stats.rays()) / renderCpu);
  std::printf("  total exact (cells + render): %.2f s wall, %.2f s CPU (idle 2-core estimate %.1f s)\n", sceneS + renderS,
              sceneCpu + renderCpu, 0.5 * (sceneCpu + renderCpu));
  if (!a.out.empty()) writeImage(image, a.out);
  if (scene.stats().implicitTapes > 0)
    std::printf("  pruned tapes: %zu distinct for %zu cells, %.1f nodes per cell (whole tape %zu nodes)\n",
                scene.stats().implicitTapes, scene.stats().implicitCells,
                double(scene.stats().implicitTapeNodes) / double(scene.stats().implicitCells), compiled.nodeCount());
  if (a.fullTape) {
    render::Scene full;
    render::ImplicitOptions fullOpt = io;
    fullOpt.prunedTapes = false;
    const auto [fullSceneS, fullSceneCpu] = woodScene(full, compiled, fullOpt, camera, a);
    render::RenderStats fullStats;
    double fullS = 0, fullCpu = 0;
    Image fullImage = timedRender(full, camera, rs, fullStats, fullS, fullCpu);
    std::printf("  full-tape baseline: surface cells %.2f s (CPU %.2f s), render %.2f s (CPU %.2f s); "
                "pruned tapes: cells CPU x%.2f, render CPU x%.2f faster\n",
                fullSceneS, fullSceneCpu, fullS, fullCpu, fullSceneCpu / sceneCpu, fullCpu / renderCpu);
    if (!a.out.empty()) writeImage(fullImage, a.out + ".full.png");
  }
  render::Scene ref;
  render::ImplicitOptions refOpt = io;
  refOpt.batched = false;
  woodScene(ref, compiled, refOpt, camera, a);
  rs.width = std::max(16, a.width / 6);
  rs.height = std::max(16, a.height / 6);
  rs.spp = 1;
  render::RenderStats fast, slow;
  double wall = 0, fastCpu = 0, slowCpu = 0;
  timedRender(scene, camera, rs, fast, wall, fastCpu);
  timedRender(ref, camera, rs, slow, wall, slowCpu);
  const double fastRate = double(fast.rays()) / fastCpu, slowRate = double(slow.rays()) / slowCpu;
  std::printf("  baseline %dx%d, 1 spp: batched %.3g rays per CPU s, per-cell reference %.3g, ratio %.2fx\n", rs.width,
              rs.height, fastRate, slowRate, fastRate / slowRate);
}

/// Polygonization at cells of 1/400 of the diagonal: the automatic size follows the
/// thinnest twig tip and would ask for billions of cells on a 2,000-internode tree.
void benchPolygonize(const blobtree::CompiledBlob& compiled) {
  const auto t = Clock::now();
  const double cpu0 = processCpuSeconds();
  blobtree::PolygonizeOptions po;
  po.cellSize = glm::length(compiled.bounds().size()) / 400.0f;
  const blobtree::PolygonizeResult mesh = blobtree::polygonizeDetailed(compiled, po);
  std::printf("polygonize: %.2f s (CPU %.2f s), cell %.4g, %zu triangles, %zu field evaluations\n", since(t),
              processCpuSeconds() - cpu0, mesh.cellSize, mesh.mesh.triangleCount(), mesh.fieldEvaluations);
}

}  // namespace

int main(int argc, char** argv) {
  const Args a = parseArgs(argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    auto t = Clock::now();
    lsystem::Skeleton skeleton = growPoplar(a.steps);
    const double growS = since(t);
    // The BlobTree: PCM junctions, bends, bark.
    organisms::TreeOptions opt;
    opt.junctions = organisms::JunctionModel::Pcm;
    opt.bends.angleDeg = a.bendDeg;
    opt.bends.orderScale = 0.8;
    opt.bends.randomness = 0.5;
    opt.bark.vScale = 6;
    t = Clock::now();
    organisms::TreeBlob blob = organisms::buildTreeBlob(skeleton, opt);
    const double buildS = since(t);
    t = Clock::now();
    blobtree::CompiledBlob compiled = blobtree::compile(blob.tree, blob.root);
    const double compileS = since(t);
    std::printf("poplar, %d steps: %zu internodes, %zu BlobTree nodes, %zu primitives\n", a.steps,
                skeleton.internodes.size(), blob.tree.size(), compiled.primitiveCount());
    std::printf("grow (derive + turtle) %.3f s, BlobTree build %.3f s, compile %.3f s\n", growS, buildS, compileS);
    benchCulling(compiled);
    if (a.width > 0) benchExactRender(compiled, a);
    benchPolygonize(compiled);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_tree: %s\n", e.what());
    return 1;
  }
  return 0;
}
