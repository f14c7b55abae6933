/// `sprig preview FILE -o OUT.png [--stage K] [--width W --height H] [--view AZ,EL[,FOV]]`

#include <algorithm>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/cmd_common.h"
#include "app/watch.h"
#include "lsystem/turtle.h"
#include "model/growth.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "render/camera.h"
#include "render/scene.h"
#include "core/image.h"
#include "core/phases.h"

namespace sprig {

namespace {

struct PreviewArgs {
  std::string file;
  std::string out;
  int stage = -1;
  int width = 0;
  int height = 0;
  int samples = 0;
  std::string view;
  GrowthFlags growth;
  WatchFlags watch;
};

int previewOnce(const PreviewArgs& a, const GlobalOptions& g) {
  PhaseClock::declare({"read", "derive", "scene", "render", "write"});
  lsystem::GrammarOverrides extra = a.growth.overrides();
  Species species = loadSpecies(a.file, g.pathPolicy());
  printNotes(g, species);
  SpeciesRender look = species.render;
  if (!a.view.empty()) parseView(a.view, look.view);
  if (a.samples > 0) look.image.spp = a.samples;

  const int lookWidth = look.image.width, lookHeight = look.image.height;
  int width = a.width > 0 ? a.width : lookWidth;
  int height = a.height > 0 ? a.height : lookHeight;
  if (a.width > 0 && a.height <= 0) height = std::max(16, lookHeight * a.width / lookWidth);
  if (a.height > 0 && a.width <= 0) width = std::max(16, lookWidth * a.height / lookHeight);

  checkCameraRays(width, height, look.image.spp);  // before anything is derived or built
  // The skeleton as derived at the step shown, framed like the final step.
  std::optional<Phase> phase(std::in_place, "read");
  GrowthEngine engine(species, GrowthOptions{extra, -1, {}});
  phase.reset();
  const int last = engine.lastStep();
  const int step = a.stage >= 0 ? std::min(a.stage, last) : last;
  if (a.stage > last && !g.quiet)
    std::cerr << "sprig: note: --stage " << a.stage << " is past the last step of '" << species.name << "' (" << last
              << "); showing step " << last << "\n";
  const lsystem::Skeleton shown = engine.skeletonAt(step);
  // Not `framingBox(step == last ? shown : ...)`: that conditional copies `shown`.
  const DBox3 frame = step == last ? framingBox(shown) : framingBox(engine.skeletonAt(last));
  const Box3 frameBox{Vec3(frame.lo), Vec3(frame.hi)};
  if (!render::boxInRenderRange(frameBox))
    throw InputError(species.loc(), "the skeleton's bounding box is not finite or reaches beyond 1e15: it cannot be rendered");
  const render::Camera camera = render::frameBounds(frameBox, look.view, static_cast<double>(width) / height);
  render::Scene scene;
  phase.emplace("scene");
  scene.setPixelFootprint(camera, width, height, look.image.thinMinPixels);
  scene.add(skeletonPreview(shown, look.style));
  scene.commit();
  phase.emplace("render");
  render::RenderSettings rs = look.settings(width, height);
  rs.progressLabel = "render " + species.name;
  Image image = render::renderImage(scene, camera, rs);
  phase.reset();
  writeImage(image, a.out);
  // cpfg's textured cylinders are meshes (organs), not internodes: counted apart.
  const size_t tubes = static_cast<size_t>(std::count_if(shown.organs.begin(), shown.organs.end(), [](const lsystem::Organ& o) {
    return o.texture >= 0 && (o.name == lsystem::kTexturedCylinderName || o.name == lsystem::kTexturedGcName);
  }));
  if (tubes > 0)
    note(g, std::cerr, "%s: %dx%d, %zu internodes, %zu textured cylinder segments", a.out.c_str(), width, height,
         shown.internodes.size(), tubes);
  else
    note(g, std::cerr, "%s: %dx%d, %zu internodes", a.out.c_str(), width, height, shown.internodes.size());
  return kExitOk;
}

int runPreview(const PreviewArgs& a, const GlobalOptions& g) {
  requireExtension("-o", a.out, {".png", ".jpg", ".jpeg", ".exr"});
  return runWatched(a.watch, g, a.file, a.out, [&] { return previewOnce(a, g); });
}

}  // namespace

void addPreviewCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<PreviewArgs>(app, global, run, "preview",
                                          "Render a shaded 3D preview of a species or grammar", runPreview);
  addInputOutput(*sub, "FILE", args->file, args->out, "output image (.png, .jpg, .exr)");
  sub->add_option("--stage", args->stage, "show the plant after this derivation step (framed as the final stage)")
      ->check(CLI::Range(0, 100000));
  sub->add_option("--width", args->width, "image width in pixels")->check(CLI::Range(16, 8192));
  sub->add_option("--height", args->height, "image height in pixels")->check(CLI::Range(16, 8192));
  sub->add_option("--samples", args->samples, "camera samples per pixel")->check(CLI::Range(1, 1024));
  sub->add_option("--view", args->view, "camera direction AZIMUTH,ELEVATION[,FOV] in degrees");
  addGrowthFlags(*sub, args->growth);
  addWatchFlags(*sub, args->watch);
}

}  // namespace sprig
