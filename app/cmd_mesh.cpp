/// `sprig mesh SPECIES -o OUT.{ply,obj,glb} [--cell SIZE] [--stage K]`: polygonizes a species' surface.

#include "app/cmd_mesh.h"

#include <chrono>
#include <cstdio>
#include <iostream>

#include "model/species.h"
#include "app/cmd_common.h"
#include "model/model.h"
#include "core/mesh_io.h"

namespace sprig {

namespace {

struct MeshArgs {
  std::string file;
  std::string out;
  double cell = 0.0;
  int stage = -1;
  double fraction = 1.0;
  double age = -1.0;
  int steps = -1;
  int64_t seed = -1;
  std::vector<std::string> defines;
};

int runMesh(const MeshArgs& a, const GlobalOptions& g) {
  requireExtension("-o", a.out, {".ply", ".obj", ".glb"});
  auto start = std::chrono::steady_clock::now();
  Species species = loadSpecies(a.file, g.pathPolicy());
  SpeciesModel model(species, commandLineOverrides(a.defines, a.steps, a.seed));
  Stage stage = a.stage >= 0 ? model.stageFromIndex(a.stage) : model.finalStage();
  stage.fraction = a.fraction;
  if (a.age >= 0) stage.age = model.stageAtAge(a.age).age;
  ModelFigures fig;
  Mesh mesh = model.buildMesh(stage, static_cast<float>(a.cell), !g.quiet, &fig);

  MeshWriteOptions wopt;
  wopt.materialName = species.name.empty() ? "sprig" : species.name;
  writeMesh(mesh, a.out, wopt);
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!g.quiet) {
    char line[256];
    std::snprintf(line, sizeof line, "%s: %zu triangles, %zu vertices, %zu primitives, built in %.2f s (total %.2f s)",
                  a.out.c_str(), mesh.triangleCount(), mesh.vertexCount(), fig.primitives, fig.buildSeconds, total);
    std::cout << line << "\n";
  }
  return kExitOk;
}

}  // namespace

void addMeshCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto args = std::make_shared<MeshArgs>();
  CLI::App* sub = app.add_subcommand("mesh", "Polygonize a species' surface into a closed triangle mesh (.ply, .obj, .glb)");
  sub->add_option("SPECIES", args->file, "species file (.yaml) or grammar (.lsys)")->required();
  sub->add_option("-o,--output", args->out, "output mesh (.ply, .obj + .mtl, .glb)")->required();
  sub->add_option("--cell", args->cell, "cell edge length in model units (default: automatic, from the smallest feature)")
      ->check(CLI::PositiveNumber);
  sub->add_option("--stage", args->stage, "tree: derivation step; shell: number of whorls grown")
      ->check(CLI::Range(0, 100000));
  sub->add_option("--fraction", args->fraction, "tree: growth of the stage's newest modules, 0..1 (default 1)")
      ->check(CLI::Range(0.0, 1.0));
  sub->add_option("--age", args->age, "shell: age θ_end in degrees (default: the species' age)")
      ->check(CLI::Range(1.0, 1e6));
  sub->add_option("--steps", args->steps, "derivation steps (trees)")->check(CLI::Range(0, 100000));
  sub->add_option("--seed", args->seed, "random seed (trees)")->check(CLI::NonNegativeNumber);
  sub->add_option("-D,--define", args->defines, "override a #define: NAME=VALUE (repeatable)");
  sub->callback([args, &global, &run] { run = [args, &global] { return runMesh(*args, global); }; });
}

}  // namespace sprig
