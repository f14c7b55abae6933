/// `sprig mesh SPECIES -o OUT.{ply,obj,glb} [--cell SIZE]`: polygonizes a species' BlobTree.

#include "app/cmd_mesh.h"

#include <chrono>
#include <cstdio>
#include <iostream>

#include "app/species.h"
#include "app/species_blob.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/mesh_io.h"

namespace sprig {

namespace {

struct MeshArgs {
  std::string file;
  std::string out;
  double cell = 0.0;
};

// The BlobTree of a species; only kind: blob species describe one directly so far.
BlobSpecies speciesBlob(const Species& species) {
  if (species.kind != SpeciesKind::Blob) {
    SourceLoc loc = species.kindNode ? species.kindNode->loc() : SourceLoc{species.file.string(), 1, 1};
    std::string line = species.yaml ? species.yaml->sourceLine(loc.line) : std::string();
    throw InputError(loc, std::string("sprig mesh takes kind: blob species, got kind: ") +
                              speciesKindName(species.kind), line);
  }
  DiagnosticList diags;
  MapReader top(species.yaml->rootNode(), diags, "species file");
  std::optional<BlobSpecies> blob = readBlobSpecies(top, diags);  // other keys: checked by loadSpecies
  diags.throwIfErrors();
  if (!blob) throw InputError(species.yaml->rootNode().loc(), "invalid blob species");
  blob->name = species.name;
  return std::move(*blob);
}

int runMesh(const MeshArgs& a, const GlobalOptions& g) {
  requireExtension("-o", a.out, {".ply", ".obj", ".glb"});
  auto start = std::chrono::steady_clock::now();
  Species species = loadSpecies(a.file, g.pathPolicy());
  BlobSpecies blob = speciesBlob(species);
  blobtree::CompiledBlob compiled = blobtree::compile(blob.tree, blob.root);

  blobtree::PolygonizeOptions opt;
  opt.cellSize = a.cell > 0 ? float(a.cell) : blob.cellSize;
  opt.progress = !g.quiet;
  auto meshStart = std::chrono::steady_clock::now();
  blobtree::PolygonizeResult r = blobtree::polygonizeDetailed(compiled, opt);
  double meshSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - meshStart).count();

  MeshWriteOptions wopt;
  wopt.materialName = blob.name.empty() ? "sprig" : blob.name;
  writeMesh(r.mesh, a.out, wopt);
  double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!g.quiet) {
    char line[256];
    std::snprintf(line, sizeof line, "%s: %zu triangles, %zu vertices, cell %.4g, polygonized in %.2f s (total %.2f s)",
                  a.out.c_str(), r.mesh.triangleCount(), r.mesh.vertexCount(), double(r.cellSize), meshSeconds, total);
    std::cout << line << "\n";
  }
  return kExitOk;
}

}  // namespace

void addMeshCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto args = std::make_shared<MeshArgs>();
  CLI::App* sub = app.add_subcommand("mesh", "Polygonize a blob species into a closed triangle mesh (.ply, .obj, .glb)");
  sub->add_option("SPECIES", args->file, "species file (.yaml) of kind: blob")->required();
  sub->add_option("-o,--output", args->out, "output mesh (.ply, .obj + .mtl, .glb)")->required();
  sub->add_option("--cell", args->cell, "cell edge length in model units (default: automatic, from the smallest feature)")
      ->check(CLI::PositiveNumber);
  sub->callback([args, &global, &run] { run = [args, &global] { return runMesh(*args, global); }; });
}

}  // namespace sprig
