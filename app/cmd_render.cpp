/// `sprig render SPECIES -o OUT.{png,exr,jpg} [--width W --height H --spp N --mode exact|mesh|skeleton
///  --stage K --fraction F --age DEG --view AZ,EL[,FOV] --camera X,Y,Z[,TX,TY,TZ] --section NX,NY,NZ,D]`

#include <cstdio>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/cmd_common.h"
#include "app/watch.h"
#include "model/model.h"
#include "model/species.h"
#include "core/image.h"
#include "core/phases.h"

namespace sprig {

namespace {

struct RenderArgs {
  std::string file;
  std::string out;
  int width = 0;
  int height = 0;
  int spp = 0;
  std::string mode = "exact";
  std::string mesher;  ///< empty = the species' render.mesher
  double simplify = -1;  ///< < 0 = the species' render.simplify
  StageFlags stage;
  std::string view;
  std::string camera;
  std::string section;
  GrowthFlags growth;
  WatchFlags watch;
};

/// Comma-separated finite numbers of magnitude at most 1e6; nullopt when one is not.
std::optional<std::vector<double>> parseNumberList(const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    auto n = parseFiniteNumber(part);
    if (!n || std::abs(*n) > 1e6) return std::nullopt;
    v.push_back(*n);
  }
  return v;
}

/// Parses `X,Y,Z` (eye) or `X,Y,Z,TX,TY,TZ` (eye and target) into look.camera.
void parseCamera(const std::string& text, SpeciesRender& look) {
  const std::optional<std::vector<double>> list = parseNumberList(text);
  const std::vector<double> v = list.value_or(std::vector<double>{});
  if (!list || (v.size() != 3 && v.size() != 6))
    throw UsageError("--camera " + text + ": expected X,Y,Z or X,Y,Z,TX,TY,TZ (eye, then target)");
  CameraSpec c;
  c.position = Vec3(float(v[0]), float(v[1]), float(v[2]));
  if (v.size() == 6) c.target = Vec3(float(v[3]), float(v[4]), float(v[5]));
  else if (look.camera && look.camera->target) c.target = look.camera->target;
  look.camera = c;
  look.closeUp.reset();  // the command line's camera replaces the species' close-up
}

int renderOnce(const RenderArgs& a, const GlobalOptions& g) {
  PhaseClock::declare({"read", "derive", "build", "cells", "scene", "render", "write"});
  const GeometryMode mode = geometryModeNamed(a.mode);
  Species species = loadSpecies(a.file, g.pathPolicy());
  printNotes(g, species);
  SpeciesRender look = species.render;
  if (!a.view.empty()) parseView(a.view, look.view);
  if (!a.camera.empty()) parseCamera(a.camera, look);
  if (!a.mesher.empty()) look.dualMesher = a.mesher == "dual";
  if (a.simplify >= 0) look.simplify = a.simplify;

  SpeciesModel model(species, a.growth.overrides());
  if (!a.section.empty()) {
    const std::optional<std::vector<double>> v = parseNumberList(a.section);
    if (!v || v->size() != 4 || glm::length(DVec3((*v)[0], (*v)[1], (*v)[2])) == 0)
      throw UsageError("--section " + a.section + ": expected NX,NY,NZ,D (the plane n·x = d; n not zero)");
    if (model.volumeMeshExtensions().empty()) throw UsageError("--section applies to solid species only");
    look.section = Vec4(float((*v)[0]), float((*v)[1]), float((*v)[2]), float((*v)[3]));
  }
  RenderJob job;
  job.width = a.width;
  job.height = a.height;
  job.samples = a.spp;
  job.mode = mode;
  job.stage = a.stage.resolve(model);
  job.progress = !g.quiet;
  job.progressLabel = "render " + species.name;

  ModelFigures fig;
  render::RenderStats stats;
  Image image = renderPicture(model, look, job, &fig, &stats);
  writeImage(image, a.out);
  note(g, std::cerr,
       "%s: %dx%d, %d spp, %s mode%s%s; %zu primitives, %zu cells, %zu triangles; "
       "%.2f Mrays/s",
       a.out.c_str(), image.width, image.height, job.samples > 0 ? job.samples : look.image.spp, geometryModeName(mode),
       model.stageName(job.stage).empty() ? "" : ", ", model.stageName(job.stage).c_str(), fig.primitives, fig.cells,
       fig.triangles, stats.raysPerSecond() / 1e6);
  return kExitOk;
}

int runRender(const RenderArgs& a, const GlobalOptions& g) {
  requireExtension("-o", a.out, {".png", ".jpg", ".jpeg", ".exr"});
  return runWatched(a.watch, g, a.file, a.out, [&] { return renderOnce(a, g); });
}

}  // namespace

void addRenderCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<RenderArgs>(app, global, run, "render",
                                          "Render a species: exact implicit surface, its mesh, or the skeleton", runRender);
  addInputOutput(*sub, "SPECIES", args->file, args->out, "output image (.png, .jpg, .exr; EXR keeps linear values)");
  sub->add_option("--width", args->width, "image width in pixels (default: the species' render.width)")
      ->check(CLI::Range(16, 16384));
  sub->add_option("--height", args->height, "image height in pixels (default: the species' render.height)")
      ->check(CLI::Range(16, 16384));
  sub->add_option("--spp,--samples", args->spp, "camera samples per pixel (default: the species' render.samples)")
      ->check(CLI::Range(1, 4096));
  sub->add_option("--mode", args->mode, "exact (ray cast the implicit surface), mesh (polygonize first) or skeleton")
      ->check(CLI::IsMember({"exact", "mesh", "skeleton"}));
  sub->add_option("--mesher", args->mesher,
                  "--mode mesh: tetrahedra (marching tetrahedra) or dual (dual marching cubes); default: the species' "
                  "render.mesher")
      ->check(CLI::IsMember({"tetrahedra", "dual"}));
  sub->add_option("--simplify", args->simplify,
                  "--mode mesh: simplify the polygonized surface while the geometric error stays below this fraction of its "
                  "extent (meshoptimizer); 0 keeps every triangle; default: the species' render.simplify (0)")
      ->check(CLI::Range(0.0, 0.1));
  addStageFlags(*sub, args->stage);
  sub->add_option("--view", args->view, "camera direction AZIMUTH,ELEVATION[,FOV] in degrees (automatic framing)");
  sub->add_option("--camera", args->camera, "explicit eye X,Y,Z or eye and target X,Y,Z,TX,TY,TZ");
  sub->add_option("--section", args->section,
                  "solids: cut away the side n·x > d of the plane NX,NY,NZ,D, showing the layers on the cut");
  addGrowthFlags(*sub, args->growth);
  addWatchFlags(*sub, args->watch);
}

}  // namespace sprig
