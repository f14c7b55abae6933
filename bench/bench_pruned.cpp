// Benchmark of the per-cell pruned tapes of the exact renderer (blobtree::SurfaceCellOptions::
// prunedTapes, render::ImplicitOptions::prunedTapes): renders species' final stages exactly,
// first with every surface cell tracing the whole tape (the baseline, same process), then
// with each cell's pruned tape, and prints both times and how many pixels differ.
//
// Usage: bench_pruned [--width 384] [--spp 1] [--out DIR] species.yaml...
//   (run from the repository root). --out DIR writes NAME-full.png and NAME-pruned.png for
//   idiff. Height keeps the species' aspect.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include "core/timer.h"
#include "model/model.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"

using namespace sprig;

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  int width = 384, spp = 1;
  std::string outDir;
  std::vector<std::string> files;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--width") && i + 1 < argc) width = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--spp") && i + 1 < argc) spp = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--out") && i + 1 < argc) outDir = argv[++i];
    else if (argv[i][0] == '-') {
      std::fprintf(stderr, "bench_pruned: unknown argument %s\n", argv[i]);
      return 2;
    } else files.push_back(argv[i]);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: bench_pruned [--width W] [--spp N] [--out DIR] species.yaml...\n");
    return 2;
  }
  try {
    for (const std::string& file : files) {
      PathPolicy policy;
      policy.root = std::filesystem::current_path();
      SpeciesModel model(loadSpecies(file, policy));
      const SpeciesRender& look = model.species().render;
      const int height = std::max(16, look.image.height * width / look.image.width);
      const render::Camera camera = modelCamera(look, model.frameBox(), width, height);
      BuiltStage built = model.build(model.finalStage(), GeometryMode::Exact, look);
      render::RenderSettings rs = look.settings(width, height);
      rs.spp = spp;
      rs.progress = false;
      Image images[2];
      double cellsCpu[2] = {}, renderCpu[2] = {};
      for (int pruned = 0; pruned < 2; ++pruned) {
        render::Geometry g = built.geometry;
        for (auto& part : g.parts)
          if (auto* im = std::get_if<render::ImplicitPart>(&part)) im->options.prunedTapes = pruned == 1;
        render::Scene scene;
        scene.setPixelFootprint(camera, width, height, look.image.thinMinPixels);
        double c0 = processCpuSeconds();
        scene.add(g);
        scene.commit();
        cellsCpu[pruned] = processCpuSeconds() - c0;
        c0 = processCpuSeconds();
        images[pruned] = render::renderImage(scene, camera, rs);
        renderCpu[pruned] = processCpuSeconds() - c0;
        if (pruned == 1 && scene.stats().implicitTapes > 0)
          std::printf("%s: %zu cells, %zu distinct pruned tapes, %.1f nodes per cell\n", file.c_str(),
                      scene.stats().implicitCells, scene.stats().implicitTapes,
                      double(scene.stats().implicitTapeNodes) / double(scene.stats().implicitCells));
      }
      size_t differ = 0;
      float worst = 0.0f;
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
          float d = 0.0f;
          for (int c = 0; c < 3; ++c) d = std::max(d, std::abs(images[0].at(x, y)[c] - images[1].at(x, y)[c]));
          differ += d > 0.0f;
          worst = std::max(worst, d);
        }
      std::printf("%s %dx%d %d spp: scene CPU %.2f s full / %.2f s pruned; render CPU %.2f s full / %.2f s pruned "
                  "(x%.2f); %zu of %d pixels differ, max %.4f\n",
                  file.c_str(), width, height, spp, cellsCpu[0], cellsCpu[1], renderCpu[0], renderCpu[1],
                  renderCpu[0] / renderCpu[1], differ, width * height, worst);
      if (!outDir.empty()) {
        const std::string stem = std::filesystem::path(file).stem().string();
        writeImage(images[0], std::filesystem::path(outDir) / (stem + "-full.png"));
        writeImage(images[1], std::filesystem::path(outDir) / (stem + "-pruned.png"));
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_pruned: %s\n", e.what());
    return 1;
  }
  return 0;
}
