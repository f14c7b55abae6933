// Benchmark of the Murex cabritii shell (Galbraith, Prusinkiewicz, Wyvill, seed 000): the
// paper's parameters (organisms::murexCabritii: seven whorls, Table 1 varices, bumps with
// the n = 400 blend, Table 2 axial spines, the CSG opening).
//
// Prints: BlobTree build time, compile time, surface-cell time, exact render time and
// rays/s at 1536x2048 (the target: under 2 minutes on 2 cores). Baseline in the
// same process: the smooth point-primitive shell (same spiral, no varices, bumps, canal,
// spines or opening) rendered the same way; the ratio says what the Murex's detail costs
// per ray.
//
// Usage: bench_shell [--width 1536] [--height 2048] [--spp 9] [--cell-div 0]
//                    [--baseline 1] [--image OUT.png] [--age DEG]
//   --cell-div N: surface cells of diagonal/N (0 = organisms::shellCellSize's choice)
//   --baseline 0 skips the baseline render
//   --canal sx,sy,length,ra,rb,turn: another canal for the Murex (organisms::CanalOptions:
//     start, length along the axis, radii, turn in degrees; unit generating frame)
//   --tolerance T: relative root tolerance (default organisms::kShellTraceTolerance = 1e-4)
//   --canal-deg DEG: sweep the canal over the last DEG degrees (the paper: 464)
//   --full-tape 1: also render the Murex with every cell tracing the whole tape
//     (ImplicitOptions::prunedTapes = false), the baseline of the per-cell pruned tapes;
//     --full-image OUT.png writes that image (compare it with --image's by idiff)
//   --without LIST leaves parts out of the Murex (cost breakdown): any of varices, bumps,
//     axial, opening, tori, spinebend, canal, axialbend,
//     ricci (bumps summed instead of the n = 400 blend)

#include <chrono>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

#include "bench/bench_view.h"
#include "blobtree/compiled.h"
#include "core/image.h"
#include "organisms/shell.h"
#include "organisms/shell_paint.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"

using namespace sprig;
using Clock = std::chrono::steady_clock;

namespace {

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Args {
  int width = 1536, height = 2048, spp = 9;
  float cellDiv = 0.0f;
  bool baseline = true;
  std::string image;
  double age = 0.0;
  std::string without;  ///< parts left out of the Murex, for a cost breakdown
  std::string canal;    ///< canal override "sx,sy,length,ra,rb,turn" (unit frame)
  double canalDeg = 0;  ///< canal sweep override (degrees before θ_end)
  float tolerance = 0;  ///< relative root tolerance (0 = organisms::kShellTraceTolerance)
  bool fullTape = false;  ///< also render the Murex without pruned tapes (baseline)
  std::string fullImage;  ///< image of that render
};

struct Result {
  double buildS = 0, compileS = 0, sceneS = 0, renderS = 0, renderCpuS = 0, raysPerS = 0;
  size_t primitives = 0, cells = 0;
  uint64_t rays = 0;
};

Result run(const organisms::ShellParams& params, const Args& a, const std::string& image, const char* label,
           bool prunedTapes = true) {
  Result r;
  auto t = Clock::now();
  organisms::ShellModel model = organisms::buildShell(params);
  r.buildS = since(t);
  t = Clock::now();
  blobtree::CompiledBlob blob = blobtree::compile(model.tree, model.root);
  r.compileS = since(t);
  r.primitives = blob.primitiveCount();
  auto painter = std::make_shared<const organisms::ShellPainter>(params, model, organisms::ShellTextureOptions{});

  t = Clock::now();
  render::Scene scene;
  // The camera framed on the blob's bounds: the one framed on the scene's below differs
  // little, and only the cost of the free sub-cells' proofs depends on it.
  scene.setExpectedSamples(bench::benchCamera(blob.bounds(), 25, 10, a.width, a.height), a.width, a.height, a.spp);
  const uint32_t material = scene.addMaterial(render::Material{painter->options().whorlColor, 0.35f, 0.05f, 0});
  for (auto part : {organisms::ShellPart::Whorl, organisms::ShellPart::VarixSpine, organisms::ShellPart::AxialSpine,
                    organisms::ShellPart::Bump, organisms::ShellPart::Inside})
    scene.addTexture([painter, part](Vec2 uv, const Vec3& p) { return painter->partColor(part, p, uv); });
  render::ImplicitOptions opt;
  opt.cellSize = a.cellDiv > 0 ? glm::length(blob.bounds().size()) / a.cellDiv : organisms::shellCellSize(blob);
  opt.trace.relativeTolerance = a.tolerance > 0 ? a.tolerance : organisms::kShellTraceTolerance;
  opt.prunedTapes = prunedTapes;
  scene.addImplicit(blob, material, opt);
  scene.commit();
  r.sceneS = since(t);
  r.cells = scene.stats().implicitCells;
  if (scene.stats().implicitTapes > 0)
    std::printf("%s: pruned tapes: %zu distinct for %zu cells, %.1f nodes per cell (whole tape %zu nodes)\n", label,
                scene.stats().implicitTapes, r.cells, double(scene.stats().implicitTapeNodes) / double(r.cells),
                blob.nodeCount());

  const render::Camera camera = bench::benchCamera(scene.bounds(), 25, 10, a.width, a.height);
  render::RenderSettings rs = bench::benchSettings(a.width, a.height, a.spp);
  render::RenderStats stats;
  t = Clock::now();
  const std::clock_t cpu0 = std::clock();
  Image img = render::renderImage(scene, camera, rs, &stats);
  r.renderS = since(t);
  r.renderCpuS = double(std::clock() - cpu0) / CLOCKS_PER_SEC;
  r.rays = stats.rays();
  r.raysPerS = stats.raysPerSecond();
  std::printf("%s: %zu primitives; build %.3f s, compile %.3f s, surface cells %.2f s (%zu cells, cell %.4g)\n", label,
              r.primitives, r.buildS, r.compileS, r.sceneS, r.cells, opt.cellSize);
  std::printf("%s: exact render %dx%d, %d spp: %.2f s (%.2f CPU-s), %.3g rays, %.3g rays/s, %.3g rays per CPU-s\n",
              label, a.width, a.height, a.spp, r.renderS, r.renderCpuS, double(r.rays), r.raysPerS,
              double(r.rays) / r.renderCpuS);
  if (!image.empty()) writeImage(img, image);
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  Args a;
  for (int i = 1; i < argc; ++i) {
    auto next = [&](const char* name) -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "bench_shell: %s needs a value\n", name);
        std::exit(2);
      }
      return argv[++i];
    };
    if (!std::strcmp(argv[i], "--width")) a.width = std::atoi(next("--width"));
    else if (!std::strcmp(argv[i], "--height")) a.height = std::atoi(next("--height"));
    else if (!std::strcmp(argv[i], "--spp")) a.spp = std::atoi(next("--spp"));
    else if (!std::strcmp(argv[i], "--cell-div")) a.cellDiv = static_cast<float>(std::atof(next("--cell-div")));
    else if (!std::strcmp(argv[i], "--baseline")) a.baseline = std::atoi(next("--baseline")) != 0;
    else if (!std::strcmp(argv[i], "--image")) a.image = next("--image");
    else if (!std::strcmp(argv[i], "--age")) a.age = std::atof(next("--age"));
    else if (!std::strcmp(argv[i], "--without")) a.without = next("--without");
    else if (!std::strcmp(argv[i], "--full-tape")) a.fullTape = std::atoi(next("--full-tape")) != 0;
    else if (!std::strcmp(argv[i], "--full-image")) a.fullImage = next("--full-image");
    else if (!std::strcmp(argv[i], "--canal")) a.canal = next("--canal");
    else if (!std::strcmp(argv[i], "--canal-deg")) a.canalDeg = std::atof(next("--canal-deg"));
    else if (!std::strcmp(argv[i], "--tolerance")) a.tolerance = static_cast<float>(std::atof(next("--tolerance")));
    else {
      std::fprintf(stderr, "bench_shell: unknown argument %s\n", argv[i]);
      return 2;
    }
  }
  try {
    organisms::ShellParams murex = organisms::murexCabritii();
    if (a.age > 0) murex.ageDeg = a.age;
    auto has = [&](const std::string& w) { return ("," + a.without + ",").find("," + w + ",") != std::string::npos; };
    if (has("varices")) murex.varices.enabled = false;
    if (has("bumps")) murex.bumps.enabled = false;
    if (has("axial")) murex.axialSpines.enabled = false;
    if (has("opening")) murex.opening.enabled = false;
    if (has("spinebend")) murex.varices.bendDeg = 0.0f;
    if (has("tori")) murex.varices.tori = false;
    if (has("canal")) murex.canal.reset();
    if (has("axialbend")) murex.axialSpines.randomBends = false;
    if (has("ricci")) murex.bumps.blendN = 1.0f;
    if (a.canalDeg > 0 && murex.canal) murex.canal->sweepDeg = a.canalDeg;
    if (!a.canal.empty() && murex.canal) {
      organisms::CanalOptions& c = *murex.canal;
      float v[6] = {};
      if (std::sscanf(a.canal.c_str(), "%f,%f,%f,%f,%f,%f", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5]) != 6) {
        std::fprintf(stderr, "bench_shell: --canal needs sx,sy,length,ra,rb,turn\n");
        return 2;
      }
      c.start = Vec2(v[0], v[1]);
      c.length = v[2];
      c.radiusStart = v[3];
      c.radiusEnd = v[4];
      c.turnDeg = v[5];
    }
    const auto total = Clock::now();
    const Result m = run(murex, a, a.image, "murex");
    std::printf("murex: build + compile + cells + render %.2f s\n", since(total));
    if (a.fullTape) {
      const Result f = run(murex, a, a.fullImage, "murex, full tape (baseline)", false);
      std::printf("pruned tapes: render %.2f s vs full tape %.2f s (x%.2f), render CPU x%.2f; "
                  "surface cells %.2f s vs %.2f s\n",
                  m.renderS, f.renderS, f.renderS / m.renderS, f.renderCpuS / m.renderCpuS, m.sceneS, f.sceneS);
    }
    if (a.baseline) {
      organisms::ShellParams smooth;
      smooth.spiral = murex.spiral;
      smooth.whorls = murex.whorls;
      smooth.whorlDeg = murex.whorlDeg;
      smooth.ageDeg = murex.ageDeg;
      const Result b = run(smooth, a, "", "smooth point shell (baseline)");
      std::printf("ratio: murex rays/s / smooth rays/s = %.2f; render time ratio %.2f\n", m.raysPerS / b.raysPerS,
                  m.renderS / b.renderS);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_shell: %s\n", e.what());
    return 1;
  }
  return 0;
}
