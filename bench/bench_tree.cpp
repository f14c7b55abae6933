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
#include <ctime>
#include <cstdlib>
#include <string>

#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/atomic_file.h"
#include "core/image.h"
#include "core/rng.h"
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

// CPU seconds of the whole process (all threads).
double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace

int main(int argc, char** argv) {
  const int steps = argc > 1 ? std::atoi(argv[1]) : 11;
  const int width = argc > 2 ? std::atoi(argv[2]) : 1536;
  const int height = argc > 3 ? std::atoi(argv[3]) : 2048;
  const int spp = argc > 4 ? std::atoi(argv[4]) : 9;
  const std::string out = argc > 5 && std::string(argv[5]) != "-" ? argv[5] : "";
  const float cell = argc > 6 ? float(std::atof(argv[6])) : 0.0f;
  const double bendDeg = argc > 7 ? std::atof(argv[7]) : 8.0;
  const bool fullTape = argc > 8 && std::atoi(argv[8]) != 0;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    // Grow the skeleton.
    auto t = Clock::now();
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
    lsystem::Skeleton skeleton = lsystem::interpret(deriver.interpret(modules), deriver.symbols(), ts);
    const double growS = since(t);

    // Build the BlobTree (PCM junctions, bends, bark).
    organisms::TreeOptions opt;
    opt.junctions = organisms::JunctionModel::Pcm;
    opt.bends.angleDeg = bendDeg;
    opt.bends.orderScale = 0.8;
    opt.bends.randomness = 0.5;
    opt.bark.vScale = 6;
    t = Clock::now();
    organisms::TreeBlob blob = organisms::buildTreeBlob(skeleton, opt);
    const double buildS = since(t);
    t = Clock::now();
    blobtree::CompiledBlob compiled = blobtree::compile(blob.tree, blob.root);
    const double compileS = since(t);
    std::printf("poplar, %d steps: %zu internodes, %zu BlobTree nodes, %zu primitives\n", steps,
                skeleton.internodes.size(), blob.tree.size(), compiled.primitiveCount());
    std::printf("grow (derive + turtle) %.3f s, BlobTree build %.3f s, compile %.3f s\n", growS, buildS, compileS);

    // Baseline: culled field evaluation vs visiting every primitive, same points.
    const Box3 b = compiled.bounds();
    std::vector<Vec3> pts(20000);
    Rng rng(7);
    for (auto& p : pts)
      p = b.lo + Vec3(float(rng.uniform()), float(rng.uniform()), float(rng.uniform())) * b.size();
    double sink = 0;
    t = Clock::now();
    for (const auto& p : pts) sink += compiled.value(p);
    const double culledS = since(t);
    const size_t bruteN = 2000;
    t = Clock::now();
    for (size_t i = 0; i < bruteN; ++i) sink -= compiled.valueNoCulling(pts[i]);
    const double bruteS = since(t);
    const double culledRate = pts.size() / culledS, bruteRate = bruteN / bruteS;
    std::printf("field evaluations: culled %.3g /s, brute force %.3g /s, ratio %.1fx (checksum %.3g)\n", culledRate,
                bruteRate, culledRate / bruteRate, sink);

    // Exact render.
    if (width > 0) {
      render::Scene scene;
      auto bark = std::make_shared<textures::BarkTexture>(textures::BarkOptions{});
      scene.addTexture([bark](Vec2 uv, const Vec3&) { return bark->color(uv); });
      const uint32_t wood = scene.addMaterial(render::Material{Vec3(0.62f, 0.60f, 0.52f), 0.7f, 0.03f, 0});
      render::ImplicitOptions io;
      io.cellSize = cell;
      t = Clock::now();
      double c0 = cpuSeconds();
      scene.addImplicit(compiled, wood, io);
      scene.commit();
      const double sceneS = since(t), sceneCpu = cpuSeconds() - c0;
      render::ViewSpec view;
      view.azimuthDeg = 20;
      view.elevationDeg = 8;
      const render::Camera camera = render::frameBounds(b, view, double(width) / height);
      render::RenderSettings rs;
      rs.width = width;
      rs.height = height;
      rs.spp = spp;
      rs.progress = false;
      render::RenderStats stats;
      t = Clock::now();
      c0 = cpuSeconds();
      Image image = render::renderImage(scene, camera, rs, &stats);
      const double renderS = since(t), renderCpu = cpuSeconds() - c0;
      std::printf("exact render %dx%d, %d spp: surface cells %.2f s (CPU %.2f s), %zu cells; render %.2f s "
                  "(CPU %.2f s), %.3g rays (%.3g camera), %.3g rays/s, %.3g rays per CPU s\n",
                  width, height, spp, sceneS, sceneCpu, scene.stats().implicitCells, renderS, renderCpu,
                  double(stats.rays()), double(stats.cameraRays), stats.raysPerSecond(),
                  double(stats.rays()) / renderCpu);
      std::printf("  total exact (cells + render): %.2f s wall, %.2f s CPU (idle 2-core estimate %.1f s)\n",
                  sceneS + renderS, sceneCpu + renderCpu, 0.5 * (sceneCpu + renderCpu));
      if (!out.empty()) writeImage(image, out);
      if (scene.stats().implicitTapes > 0)
        std::printf("  pruned tapes: %zu distinct for %zu cells, %.1f nodes per cell (whole tape %zu nodes)\n",
                    scene.stats().implicitTapes, scene.stats().implicitCells,
                    double(scene.stats().implicitTapeNodes) / double(scene.stats().implicitCells), compiled.nodeCount());

      if (fullTape) {
        // Baseline: the same render with every cell tracing the whole tape.
        render::Scene full;
        full.addTexture([bark](Vec2 uv, const Vec3&) { return bark->color(uv); });
        full.addMaterial(render::Material{Vec3(0.62f, 0.60f, 0.52f), 0.7f, 0.03f, 0});
        render::ImplicitOptions fullOpt = io;
        fullOpt.prunedTapes = false;
        t = Clock::now();
        c0 = cpuSeconds();
        full.addImplicit(compiled, wood, fullOpt);
        full.commit();
        const double fullSceneS = since(t), fullSceneCpu = cpuSeconds() - c0;
        render::RenderStats fullStats;
        t = Clock::now();
        c0 = cpuSeconds();
        Image fullImage = render::renderImage(full, camera, rs, &fullStats);
        const double fullS = since(t), fullCpu = cpuSeconds() - c0;
        std::printf("  full-tape baseline: surface cells %.2f s (CPU %.2f s), render %.2f s (CPU %.2f s); "
                    "pruned tapes: cells CPU x%.2f, render CPU x%.2f faster\n",
                    fullSceneS, fullSceneCpu, fullS, fullCpu, fullSceneCpu / sceneCpu, fullCpu / renderCpu);
        if (!out.empty()) writeImage(fullImage, out + ".full.png");
      }

      // Baseline: the reference per-cell tracer vs the batched one, same scene, small image.
      render::Scene ref;
      ref.addTexture([bark](Vec2 uv, const Vec3&) { return bark->color(uv); });
      ref.addMaterial(render::Material{Vec3(0.62f, 0.60f, 0.52f), 0.7f, 0.03f, 0});
      render::ImplicitOptions refOpt = io;
      refOpt.batched = false;
      ref.addImplicit(compiled, wood, refOpt);
      ref.commit();
      rs.width = std::max(16, width / 6);
      rs.height = std::max(16, height / 6);
      rs.spp = 1;
      render::RenderStats fast, slow;
      c0 = cpuSeconds();
      render::renderImage(scene, camera, rs, &fast);
      const double fastCpu = cpuSeconds() - c0;
      c0 = cpuSeconds();
      render::renderImage(ref, camera, rs, &slow);
      const double slowCpu = cpuSeconds() - c0;
      const double fastRate = double(fast.rays()) / fastCpu, slowRate = double(slow.rays()) / slowCpu;
      std::printf("  baseline %dx%d, 1 spp: batched %.3g rays per CPU s, per-cell reference %.3g, ratio %.2fx\n",
                  rs.width, rs.height, fastRate, slowRate, fastRate / slowRate);
    }

    // Mesh.
    t = Clock::now();
    const double meshCpu0 = cpuSeconds();
    // Cells at 1/400 of the diagonal: the automatic size follows the thinnest twig tip and
    // would ask for billions of cells on a 2,000-internode tree.
    blobtree::PolygonizeOptions po;
    po.cellSize = glm::length(b.size()) / 400.0f;
    const blobtree::PolygonizeResult mesh = blobtree::polygonizeDetailed(compiled, po);
    const double meshS = since(t), meshCpu = cpuSeconds() - meshCpu0;
    std::printf("polygonize: %.2f s (CPU %.2f s), cell %.4g, %zu triangles, %zu field evaluations\n", meshS, meshCpu,
                mesh.cellSize, mesh.mesh.triangleCount(), mesh.fieldEvaluations);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_tree: %s\n", e.what());
    return 1;
  }
  return 0;
}
