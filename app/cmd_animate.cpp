/// `sprig animate SPECIES -o OUT [--stages A..B] [--frames-per-stage K] [--fps F] [--width W --height H]`
/// and `sprig animate SPECIES -o FRAME.png --at STAGE:FRACTION` (one frame, same bytes as in the animation).

#include <iostream>

#include "model/animate.h"
#include "model/kind_name.h"
#include "model/tree_kind.h"
#include "app/cmd_common.h"
#include "model/model.h"
#include "model/species.h"
#include "core/image.h"
#include "core/phases.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

struct AnimateArgs {
  std::string file;
  std::string out;
  std::string stages;
  std::string at;
  int framesPerStage = 6;
  double fps = 12;
  double hold = 0;
  int width = 0;
  int height = 0;
  int samples = 0;
  std::string wind;
  double windSeconds = 4;
  std::string mode;  ///< empty = the species' default (SpeciesModel::defaultMode)
  GrowthFlags growth;
};

/// Parses `A..B` (either side may be empty: `..B`, `A..`) into first/last (-1 = default).
void parseStages(const std::string& text, int& first, int& last) {
  const size_t dots = text.find("..");
  auto number = [&](const std::string& part, int fallback) {
    if (part.empty()) return fallback;
    auto v = parseFiniteNumber(part);
    if (!v || *v < 0 || *v > 100000 || *v != static_cast<int>(*v))
      throw UsageError("--stages " + text + ": expected A..B with whole numbers 0 <= A <= B");
    return static_cast<int>(*v);
  };
  if (dots == std::string::npos) {
    first = last = number(text, -1);
    if (first < 0) throw UsageError("--stages " + text + ": expected A..B with whole numbers 0 <= A <= B");
    return;
  }
  first = number(text.substr(0, dots), 0);
  last = number(text.substr(dots + 2), -1);
  if (last >= 0 && first > last) throw UsageError("--stages " + text + ": A must not exceed B");
}

/// Parses `STAGE` or `STAGE:FRACTION` (fraction in [0, 1], default 1).
GrowthFrame parseAt(const std::string& text) {
  const size_t colon = text.find(':');
  auto stage = parseFiniteNumber(text.substr(0, colon));
  std::optional<double> fraction = 1.0;
  if (colon != std::string::npos) fraction = parseFiniteNumber(text.substr(colon + 1));
  if (!stage || *stage < 0 || *stage != static_cast<int>(*stage) || !fraction || *fraction < 0 || *fraction > 1)
    throw UsageError("--at " + text + ": expected STAGE[:FRACTION] with a whole stage and a fraction in [0, 1]");
  return {static_cast<int>(*stage), *fraction};
}

int runAnimate(const AnimateArgs& a, const GlobalOptions& g) {
  PhaseClock::declare({"read", "derive", "build", "cells", "scene", "render", "write"});
  AnimateOptions opt;
  opt.extra = a.growth.overrides();
  opt.framesPerStage = a.framesPerStage;
  opt.fps = a.fps;
  opt.holdSeconds = a.hold;
  opt.samples = a.samples;
  if (!a.stages.empty()) parseStages(a.stages, opt.firstStage, opt.lastStage);
  if (!a.wind.empty()) {
    parseWind(a.wind, opt.windSpeed, opt.windDirectionDeg);
    if (!a.at.empty()) throw UsageError("--wind sways an animation over time; --at renders one still frame");
  }
  opt.windSeconds = a.windSeconds;
  if (!a.mode.empty()) opt.mode = geometryModeNamed(a.mode);
  std::optional<GrowthFrame> single;
  if (!a.at.empty()) {
    requireExtension("-o", a.out, {".png", ".jpg", ".jpeg", ".exr"});
    single = parseAt(a.at);
  } else {
    try {
      animationFormatFor(a.out);
    } catch (const std::invalid_argument& e) {
      throw UsageError(e.what());
    }
  }
  Species species = loadSpecies(a.file, g.pathPolicy());
  printNotes(g, species);
  if (species.kind != "tree" && !a.wind.empty())
    throw UsageError("--wind sways trees; " + speciesOfKind(species.kind) + " has no wind");
  if (species.kind != "tree" && species.kind != "solid" && !a.stages.empty())
    throw UsageError("--stages selects derivation steps of a tree or operation stages of a solid; " +
                     speciesOfKind(species.kind) + " animates its whole growth (use --frames-per-stage and --fps)");
  const SpeciesRender& look = species.render;
  if (look.pair)
    note(g, std::cerr, "sprig: note: render.pair ('%s') pairs the picture only (sprig render, the gallery's final stage); the animation shows '%s' alone",
         look.pair->filename().c_str(), species.name.c_str());
  const int lookWidth = look.image.width, lookHeight = look.image.height;
  opt.width = a.width > 0 ? a.width : lookWidth;
  opt.height = a.height > 0 ? a.height : lookHeight;
  if (a.width > 0 && a.height <= 0) opt.height = std::max(16, lookHeight * a.width / lookWidth);
  if (a.height > 0 && a.width <= 0) opt.width = std::max(16, lookWidth * a.height / lookHeight);
  opt.progressLabel = "animate " + species.name;

  if (single) {
    SpeciesModel model(species, opt.extra, opt.lastStage);
    SpeciesRender frameLook = look;
    if (a.samples > 0) frameLook.image.spp = a.samples;
    RenderJob job;
    job.width = opt.width;
    job.height = opt.height;
    job.mode = opt.mode ? *opt.mode : model.defaultMode();
    job.stage = model.stageFromIndex(single->stage);
    job.stage.fraction = single->fraction;
    job.progress = false;
    writeImage(renderModel(model, frameLook, job), a.out);
    if (!g.quiet) std::cerr << a.out << ": " << model.stageName(job.stage) << "\n";
    return kExitOk;
  }
  AnimateResult r = animateSpecies(species, a.out, opt);
  if (!g.quiet)
    std::cerr << a.out << ": " << r.frames << " frames, "
              << (species.kind == "tree" || (species.kind == "solid" && r.lastStage > 0)
                      ? "stages " + std::to_string(r.firstStage) + ".." + std::to_string(r.lastStage) + ", "
                      : std::string())
              << opt.width << "x" << opt.height << ", " << r.seconds << " s\n";
  return kExitOk;
}

}  // namespace

void addAnimateCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<AnimateArgs>(app, global, run, "animate",
                                          "Render a species growing, stage by stage, with smooth growth between steps", runAnimate);
  addInputOutput(*sub, "SPECIES", args->file, args->out,
                 "a folder (PNG frames), .gif or .mp4 (needs ffmpeg); .png with --at");
  sub->add_option("--stages", args->stages, "stages shown, A..B: a tree's derivation steps, a solid's operations "
                  "(stage k = after k operations; default: 0 to the last)");
  sub->add_option("--frames-per-stage", args->framesPerStage, "frames over which one step's new organs grow in")
      ->check(CLI::Range(1, 1000));
  sub->add_option("--fps", args->fps, "frames per second of the GIF or MP4")->check(CLI::Range(0.1, 240.0));
  sub->add_option("--hold", args->hold, "GIF and MP4: seconds to show the grown plant before looping")
      ->check(CLI::Range(0.0, 60.0));
  sub->add_option("--at", args->at, "render the single frame STAGE[:FRACTION] to a PNG instead");
  sub->add_option("--mode", args->mode,
                  "exact (ray cast the implicit surface), mesh (polygonize first) or skeleton, as `sprig render --mode`; "
                  "default: exact for species with a surface, skeleton for other trees")
      ->check(CLI::IsMember({"exact", "mesh", "skeleton"}));
  sub->add_option("--width", args->width, "frame width in pixels")->check(CLI::Range(16, 8192));
  sub->add_option("--height", args->height, "frame height in pixels")->check(CLI::Range(16, 8192));
  sub->add_option("--samples", args->samples, "camera samples per pixel")->check(CLI::Range(1, 1024));
  sub->add_option("--wind", args->wind,
                  "SPEED[,DIRECTION]: sway a tree in wind of SPEED m/s blowing toward azimuth DIRECTION degrees "
                  "(default 0: toward +Z), alone or on top of growth");
  sub->add_option("--wind-seconds", args->windSeconds,
                  "with --wind: the animation lasts at least this long, holding the last stage (default 4)")
      ->check(CLI::Range(0.0, 600.0));
  addGrowthFlags(*sub, args->growth);
}

}  // namespace sprig
