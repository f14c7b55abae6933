#include "gallery/gallery.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iterator>
#include <utility>

#include "core/progress.h"
#include "core/timer.h"
#include "model/animate.h"
#include "model/model.h"
#include "model/species.h"
#include "core/image.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

/// s with HTML's special characters as entities.
std::string html(const std::string& s) {
  static const std::pair<char, const char*> kEntities[] = {{'&', "&amp;"}, {'<', "&lt;"}, {'>', "&gt;"}, {'"', "&quot;"}};
  std::string out;
  for (char c : s) {
    const auto* e = std::find_if(std::begin(kEntities), std::end(kEntities), [c](const auto& p) { return p.first == c; });
    if (e != std::end(kEntities)) out += e->second;
    else out.push_back(c);
  }
  return out;
}

/// The gallery's growth animation of model as a GIF at out: stages 0..steps (or a turntable
/// for kinds that do not grow), half of width x height, a few frames per stage (draft: about
/// 36 frames in all, 2 samples; final: about 120, the look's samples). Returns the frames.
int renderGalleryAnimation(SpeciesModel& model, const fs::path& out, const SpeciesRender& look, int width, int height,
                           bool final) {
  const int w = std::max(16, width / 2), h = std::max(16, height / 2);
  const bool exact = model.hasSurfaceSettings();
  const int samples = final ? look.image.spp : std::min(look.image.spp, exact ? 1 : 2);
  const GalleryMotion motion = model.galleryMotion(final);
  const std::string& name = model.species().name;
  if (motion.turntable) {
    // A turntable around the one stage, one camera distance throughout.
    const int n = final ? 48 : 8;
    std::vector<Image> frames;
    Progress bar("turntable " + name, static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) {
      SpeciesRender turn = look;
      turn.view.azimuthDeg = look.view.azimuthDeg + 360.0 * i / n;
      RenderJob job;
      job.width = w;
      job.height = h;
      job.samples = samples;
      job.mode = GeometryMode::Exact;
      job.progress = false;
      frames.push_back(renderModel(model, turn, job));
      bar.advance();
    }
    bar.finish();
    writeAnimatedGif(frames, final ? 16 : 8, out);
    return n;
  }
  AnimateOptions opt;
  opt.framesPerStage = motion.framesPerStage;
  opt.fps = final ? 12 : 8;
  opt.holdSeconds = 1;
  opt.width = w;
  opt.height = h;
  opt.samples = samples;
  opt.progressLabel = "animate " + name;
  opt.windSpeed = look.windSpeed;  // trees only (the species reader refuses it elsewhere)
  opt.windDirectionDeg = look.windDirectionDeg;
  return animateModel(model, look, out, opt).frames;
}

std::string fixed(double v, int digits) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

}  // namespace

GalleryItem renderGalleryItem(const fs::path& speciesFile, const fs::path& outDir, GalleryQuality quality,
                              const PathPolicy& policy) {
  GalleryItem item;
  item.source = speciesFile.string();
  item.name = speciesFile.stem().string();
  try {
    Species species = loadSpecies(speciesFile, policy);
    item.name = species.name;
    item.description = species.description;
    item.kind = species.kind;
    SpeciesModel model(species);
    const GeometryMode mode = model.defaultMode();
    item.mode = geometryModeName(mode);
    SpeciesRender look = species.render;
    int width = look.image.width, height = look.image.height;
    const bool draft = quality == GalleryQuality::Draft;
    const bool exact = mode != GeometryMode::Skeleton;
    if (draft) {
      // Draft keeps the whole shipped gallery fast: skeleton previews at about 0.25
      // megapixel and 4 samples, exact surfaces (ten times the cost per ray) at 0.16
      // megapixel and 2 samples.
      const double pixels = exact ? 160000.0 : 250000.0;
      double scale = std::min(1.0, std::sqrt(pixels / (static_cast<double>(width) * height)));
      width = std::max(16, static_cast<int>(width * scale));
      height = std::max(16, static_cast<int>(height * scale));
      look.image.spp = std::min(look.image.spp, exact ? 2 : 4);
    }
    const std::string stem = speciesFile.stem().string();
    item.preview = stem + ".png";
    item.strip = stem + "_stages.png";

    // The final stage, full size.
    auto r0 = std::chrono::steady_clock::now();
    RenderJob job;
    job.width = width;
    job.height = height;
    job.mode = mode;
    job.stage = model.finalStage();
    job.progressLabel = "render " + stem;
    ModelFigures fig;
    Image preview = renderModel(model, look, job, &fig);
    writeImage(preview, outDir / item.preview);
    item.steps = std::max(0, job.stage.step);
    item.modules = fig.modules;
    item.internodes = fig.internodes;
    item.primitives = fig.primitives;
    item.triangles = fig.triangles;
    item.deriveSeconds = fig.buildSeconds;

    // The growth strip: every stage framed like the final one. A solid does not grow: its
    // strip is the whole solid and its cut-away by the plane z = 0 (Fig. 3e, 3f); a solid
    // with operations shows its sequence instead, one cell per operation (Fig. 6-8).
    const bool solid = !model.volumeMeshExtensions().empty();
    const std::vector<Stage> sequence = solid ? model.stripStages(0) : std::vector<Stage>{};
    const bool cutAway = solid && sequence.size() <= 1;
    const std::vector<Stage> stages = cutAway ? std::vector<Stage>{job.stage, job.stage} : solid ? sequence : model.stripStages(5);
    for (const Stage& st : stages)
      item.stages.push_back(model.stageNumber(st));
    const int stripHeight = std::max(16, height * 2 / 3);
    const int cellWidth = std::max(16, stripHeight * 3 / 4);
    SpeciesRender stripLook = look;
    stripLook.view.margin = std::max(look.view.margin, 0.04);
    Image strip(cellWidth * static_cast<int>(stages.size()), stripHeight);
    for (size_t i = 0; i < stages.size(); ++i) {
      RenderJob cellJob = job;
      cellJob.width = cellWidth;
      cellJob.height = stripHeight;
      cellJob.stage = stages[i];
      if (draft && exact) cellJob.samples = 1;
      cellJob.progressLabel = "stages " + stem + " " + std::to_string(i + 1) + "/" + std::to_string(stages.size());
      SpeciesRender cellLook = stripLook;
      if (cutAway && i == 1) cellLook.section = look.section.value_or(Vec4(0, 0, 1, 0));
      Image cell = renderModel(model, cellLook, cellJob);
      for (int y = 0; y < stripHeight; ++y)
        for (int x = 0; x < cellWidth; ++x) strip.set(static_cast<int>(i) * cellWidth + x, y, cell.at(x, y));
    }
    writeImage(strip, outDir / item.strip);

    item.animation = stem + ".gif";
    item.frames = renderGalleryAnimation(model, outDir / item.animation, look, width, height,
                                         quality == GalleryQuality::Final);
    item.renderSeconds = secondsSince(r0);
  } catch (const InputError& e) {
    item.error = e.what();
    item.preview.clear();
    item.strip.clear();
    item.animation.clear();
  }
  return item;
}

std::string galleryIndexHtml(const std::vector<GalleryItem>& items) {
  std::string o;
  o += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>Sprig gallery</title>\n<style>\n"
       "body{font-family:system-ui,sans-serif;margin:24px;background:#f4f3ef;color:#222}\n"
       "h1{font-weight:600}\n.item{background:#fff;border-radius:8px;padding:16px;margin:0 0 20px;"
       "box-shadow:0 1px 3px rgba(0,0,0,.15);display:flex;gap:20px;flex-wrap:wrap}\n"
       ".item img{border-radius:4px;display:block}\n.preview img{height:300px}\n.strip img{height:200px}\n"
       ".animation img{height:200px}\n"
       ".meta{min-width:240px;max-width:420px}\n.meta h2{margin:0 0 6px}\n.figs{color:#555;font-size:14px}\n"
       ".figs td{padding:1px 10px 1px 0}\n.error{color:#a00;white-space:pre-wrap;font-family:monospace}\n"
       "</style>\n</head>\n<body>\n<h1>Sprig gallery</h1>\n<p>" +
       std::to_string(items.size()) +
       " species. Each shows the final stage, a strip of growth stages and its growth animation. "
       "<a href=\"contact_sheet.png\">Contact sheet</a>.</p>\n";
  for (const auto& it : items) {
    o += "<div class=\"item\" id=\"" + html(fs::path(it.source).stem().string()) + "\">\n<div class=\"meta\">\n<h2>" +
         html(it.name) + "</h2>\n<p>" + html(it.description) + "</p>\n";
    if (!it.error.empty()) {
      o += "<p class=\"error\">" + html(it.error) + "</p>\n</div>\n</div>\n";
      continue;
    }
    std::string stages;
    for (size_t i = 0; i < it.stages.size(); ++i) stages += (i ? ", " : "") + std::to_string(it.stages[i]);
    o += "<table class=\"figs\">\n<tr><td>source</td><td>" + html(it.source) + "</td></tr>\n<tr><td>kind</td><td>" +
         html(it.kind) + "</td></tr>\n<tr><td>render mode</td><td>" + html(it.mode) + "</td></tr>\n<tr><td>steps</td><td>" + std::to_string(it.steps) +
         "</td></tr>\n<tr><td>modules</td><td>" + std::to_string(it.modules) + "</td></tr>\n<tr><td>internodes</td><td>" +
         std::to_string(it.internodes) + "</td></tr>\n<tr><td>primitives</td><td>" + std::to_string(it.primitives) +
         "</td></tr>\n<tr><td>triangles</td><td>" + std::to_string(it.triangles) +
         "</td></tr>\n<tr><td>build</td><td class=\"time\">" + fixed(it.deriveSeconds, 3) +
         " s</td></tr>\n<tr><td>render</td><td class=\"time\">" + fixed(it.renderSeconds, 2) +
         " s</td></tr>\n<tr><td>stages</td><td>" +
         stages + "</td></tr>\n</table>\n</div>\n";
    o += "<div class=\"preview\"><a href=\"" + html(it.preview) + "\"><img src=\"" + html(it.preview) + "\" alt=\"" +
         html(it.name) + "\"></a></div>\n";
    o += "<div class=\"strip\"><a href=\"" + html(it.strip) + "\"><img src=\"" + html(it.strip) + "\" alt=\"" +
         html(it.name) + " growth stages\"></a></div>\n";
    if (!it.animation.empty())
      o += "<div class=\"animation\"><a href=\"" + html(it.animation) + "\"><img src=\"" + html(it.animation) +
           "\" alt=\"" + html(it.name) + " growing (" + std::to_string(it.frames) + " frames)\"></a></div>\n";
    o += "</div>\n";
  }
  o += "</body>\n</html>\n";
  return o;
}

}  // namespace sprig
