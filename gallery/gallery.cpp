#include "gallery/gallery.h"

#include <algorithm>
#include <cctype>
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
    FrameSequence sequence(model);  // one stage: a scene that serves every turned camera is built once
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
      frames.push_back(sequence.render(turn, job));
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
  opt.holdFirst = true;  // the page's first glimpse (and the GIF's first frame) is the grown form
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
    Image preview = renderPicture(model, look, job, &fig);
    writeImage(preview, outDir / item.preview);
    item.steps = std::max(0, job.stage.step);
    item.modules = fig.modules;
    item.internodes = fig.internodes;
    item.primitives = fig.primitives;
    item.triangles = fig.triangles;
    item.deriveSeconds = fig.buildSeconds;
    item.stillSeconds = secondsSince(r0);

    // The growth strip: every stage framed like the final one. A solid does not grow: its
    // strip is the whole solid and its cut-away by render.section or the plane z = 0 (Fig. 3e, 3f); a solid
    // with operations shows its sequence instead, one cell per operation (Fig. 6-8).
    const bool solid = !model.volumeMeshExtensions().empty();
    const std::vector<Stage> sequence = solid ? model.stripStages(0) : std::vector<Stage>{};
    const bool cutAway = solid && sequence.size() <= 1;
    const std::vector<Stage> stages = cutAway ? std::vector<Stage>{job.stage, job.stage} : solid ? sequence : model.stripStages(5);
    for (const Stage& st : stages)
      item.stages.push_back(model.stageNumber(st));
    const int stripHeight = std::max(16, height * 2 / 3);
    const int cellWidth = std::max(16, stripHeight * 3 / 4);
    // Draft strips and animations, at one sample per pixel, skip the renderer's second pass
    // (RenderSettings::refineSamples): it re-traces a marked pixel's sample and 8 more, and
    // at one sample most sky-lit pixels are marked; it took the draft gallery from 259 s
    // to 349 s (docs/PERFORMANCE.md). Stills keep it.
    SpeciesRender motionLook = look;
    if (draft) motionLook.image.refineSamples = 0;
    SpeciesRender stripLook = motionLook;
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
      // The whole solid, then its cut: the species' render.section, else the plane z = 0.
      if (cutAway && i == 0) cellLook.section.reset();
      if (cutAway && i == 1) cellLook.section = look.section.value_or(Vec4(0, 0, 1, 0));
      Image cell = renderModel(model, cellLook, cellJob);
      for (int y = 0; y < stripHeight; ++y)
        for (int x = 0; x < cellWidth; ++x) strip.set(static_cast<int>(i) * cellWidth + x, y, cell.at(x, y));
    }
    writeImage(strip, outDir / item.strip);
    item.stripSeconds = secondsSince(r0) - item.stillSeconds;

    item.animation = stem + ".gif";
    item.frames = renderGalleryAnimation(model, outDir / item.animation, motionLook, width, height,
                                         quality == GalleryQuality::Final);
    item.renderSeconds = secondsSince(r0);
    item.animationSeconds = item.renderSeconds - item.stillSeconds - item.stripSeconds;
  } catch (const InputError& e) {
    item.error = e.what();
    item.preview.clear();
    item.strip.clear();
    item.animation.clear();
  }
  return item;
}

namespace {

/// A kind's heading in the index, in the order the index shows them.
struct KindGroup {
  const char* kind;
  const char* heading;
};
constexpr KindGroup kKindGroups[] = {
    {"tree", "Trees"}, {"shell", "Shells"}, {"organism", "Organisms"}, {"solid", "Solids"}, {"blob", "BlobTree models"}};

/// The figure sets of the papers, recognized by the species file's name.
struct FigureSet {
  const char* prefix;
  const char* title;
};
constexpr FigureSet kFigureSets[] = {
    {"abop_", "ABOP (Prusinkiewicz, Lindenmayer)"},
    {"fig_tree_", "BlobTree Trees (Galbraith et al.)"},
    {"blob_", "BlobTree blends and offsets"},
    {"fig_shell_", "Murex cabritii shell (Galbraith et al.)"},
    {"fig_org_", "Shapes on subdivision surfaces (Velho et al.)"},
    {"fig_solid_", "Layered solid models (Cutler et al.)"},
};

std::string stemOf(const GalleryItem& it) { return fs::path(it.source).stem().string(); }

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

const char* pageStyle() {
  return "body{font-family:system-ui,sans-serif;margin:0;background:#f4f3ef;color:#222}\n"
         "header{position:sticky;top:0;z-index:1;background:#2f3a2c;color:#eee;padding:10px 24px;display:flex;"
         "gap:16px;align-items:center;flex-wrap:wrap}\n"
         "header h1{font-size:20px;margin:0;font-weight:600}header a{color:#cfe3c0}\n"
         "#filter{font-size:16px;padding:6px 10px;border-radius:6px;border:0;min-width:260px}\n"
         "nav a{margin-right:12px}\n.sets button{margin:2px;border:1px solid #888;background:#fff;border-radius:12px;"
         "padding:2px 10px;cursor:pointer;font-size:13px}\n"
         "main{padding:8px 24px 40px}\nsection h2{margin:24px 0 8px;font-weight:600}\n"
         ".grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(200px,1fr));gap:12px}\n"
         ".card{background:#fff;border-radius:8px;overflow:hidden;box-shadow:0 1px 3px rgba(0,0,0,.15);"
         "text-decoration:none;color:inherit;display:flex;flex-direction:column}\n"
         ".card:hover{box-shadow:0 2px 8px rgba(0,0,0,.3)}\n.card img{width:100%;height:auto;display:block;"
         "aspect-ratio:4/3;background:#e6e5e0}\n"
         ".card .name{padding:6px 8px 0;font-weight:600;font-size:14px}\n.card .set{padding:0 8px 8px;color:#666;"
         "font-size:12px}\n.card.failed{border:2px solid #a00}\n"
         ".count{color:#cfe3c0;font-size:14px}\n"
         ".page img{max-width:100%;border-radius:4px;display:block}\n.page figure{margin:16px 0}\n"
         ".page figcaption{color:#555;font-size:14px;margin-top:4px}\n"
         ".figs{color:#333;font-size:14px;border-collapse:collapse}\n.figs td{padding:2px 14px 2px 0}\n"
         ".error{color:#a00;white-space:pre-wrap;font-family:monospace}\n";
}

}  // namespace

std::string galleryFigureSet(const std::string& stem) {
  for (const FigureSet& f : kFigureSets)
    if (stem.rfind(f.prefix, 0) == 0) return f.title;
  return {};
}

std::string galleryPageFile(const GalleryItem& item) { return "pages/" + stemOf(item) + ".html"; }

std::string galleryThumbFile(const GalleryItem& item) {
  return item.preview.empty() ? std::string() : "thumbs/" + stemOf(item) + ".png";
}

std::string galleryIndexHtml(const std::vector<GalleryItem>& items) {
  std::string o;
  o += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>Sprig gallery</title>\n"
       "<link rel=\"icon\" href=\"data:,\">\n<style>\n";
  o += pageStyle();
  o += "</style>\n</head>\n<body>\n<header>\n<h1>Sprig gallery</h1>\n"
       "<input type=\"search\" id=\"filter\" placeholder=\"Filter by name, kind, figure, file\" "
       "aria-label=\"Filter species\" autofocus>\n<span class=\"count\" id=\"count\">" +
       std::to_string(items.size()) + " species</span>\n<nav>";
  // Groups in a fixed order, then any other kind.
  std::vector<std::pair<std::string, std::string>> groups;
  for (const KindGroup& g : kKindGroups) groups.emplace_back(g.kind, g.heading);
  for (const auto& it : items)
    if (std::none_of(groups.begin(), groups.end(), [&](const auto& g) { return g.first == it.kind; }))
      groups.emplace_back(it.kind, it.kind.empty() ? "Failed" : it.kind);
  for (const auto& group : groups) {
    const std::string& kind = group.first;  // (clang 14: lambdas cannot capture structured bindings)
    const auto n = std::count_if(items.begin(), items.end(), [&](const GalleryItem& it) { return it.kind == kind; });
    if (n > 0) o += "<a href=\"#kind-" + html(kind) + "\">" + html(group.second) + " (" + std::to_string(n) + ")</a>";
  }
  o += "<a href=\"contact_sheet.png\">contact sheet</a></nav>\n<div class=\"sets\">";
  for (const FigureSet& f : kFigureSets) {
    const bool used = std::any_of(items.begin(), items.end(),
                                  [&](const GalleryItem& it) { return stemOf(it).rfind(f.prefix, 0) == 0; });
    if (used) o += "<button type=\"button\" data-q=\"" + html(lower(f.title)) + "\">" + html(f.title) + "</button>";
  }
  o += "</div>\n</header>\n<main>\n";
  for (const auto& [kind, heading] : groups) {
    std::string cards;
    for (const auto& it : items) {
      if (it.kind != kind) continue;
      const std::string stem = stemOf(it), set = galleryFigureSet(stem);
      const std::string search = lower(it.name + " " + it.description + " " + it.kind + " " + set + " " + stem);
      cards += "<a class=\"card" + std::string(it.error.empty() ? "" : " failed") + "\" href=\"" +
               html(galleryPageFile(it)) + "\" data-search=\"" + html(search) + "\">";
      if (!it.preview.empty())
        cards += "<img src=\"" + html(galleryThumbFile(it)) + "\" width=\"320\" height=\"240\" alt=\"" + html(it.name) +
                 "\">";
      cards += "<span class=\"name\">" + html(it.name) + "</span><span class=\"set\">" +
               html(set.empty() ? stem : set + " · " + stem) + "</span></a>\n";
    }
    if (cards.empty()) continue;
    o += "<section id=\"kind-" + html(kind) + "\">\n<h2>" + html(heading) + "</h2>\n<div class=\"grid\">\n" + cards +
         "</div>\n</section>\n";
  }
  o += "</main>\n<script>\n"
       "const box = document.getElementById('filter'), count = document.getElementById('count');\n"
       "function apply() {\n"
       "  const words = box.value.toLowerCase().split(/\\s+/).filter(w => w);\n"
       "  let shown = 0;\n"
       "  for (const s of document.querySelectorAll('section')) {\n"
       "    let n = 0;\n"
       "    for (const c of s.querySelectorAll('.card')) {\n"
       "      const ok = words.every(w => c.dataset.search.includes(w));\n"
       "      c.hidden = !ok; if (ok) n++;\n"
       "    }\n"
       "    s.hidden = n === 0; shown += n;\n"
       "  }\n"
       "  count.textContent = shown + ' of " +
       std::to_string(items.size()) +
       " species';\n"
       "  history.replaceState(null, '', words.length ? '#q=' + encodeURIComponent(box.value) : location.pathname);\n"
       "}\n"
       "box.addEventListener('input', apply);\n"
       "for (const b of document.querySelectorAll('.sets button'))\n"
       "  b.addEventListener('click', () => { box.value = b.dataset.q; apply(); });\n"
       "if (location.hash.startsWith('#q=')) { box.value = decodeURIComponent(location.hash.slice(3)); apply(); }\n"
       "</script>\n</body>\n</html>\n";
  return o;
}

std::string gallerySpeciesPageHtml(const std::vector<GalleryItem>& items, size_t index) {
  const GalleryItem& it = items.at(index);
  const std::string stem = stemOf(it), set = galleryFigureSet(stem);
  std::string o;
  o += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
       html(it.name) + " · Sprig gallery</title>\n<link rel=\"icon\" href=\"data:,\">\n<style>\n";
  o += pageStyle();
  o += "</style>\n</head>\n<body>\n<header>\n<h1>" + html(it.name) + "</h1>\n<nav><a href=\"../index.html\">all species</a>";
  if (index > 0) o += "<a href=\"" + html(stemOf(items[index - 1])) + ".html\">&larr; " + html(items[index - 1].name) + "</a>";
  if (index + 1 < items.size())
    o += "<a href=\"" + html(stemOf(items[index + 1])) + ".html\">" + html(items[index + 1].name) + " &rarr;</a>";
  o += "</nav>\n</header>\n<main class=\"page\">\n";
  if (!it.description.empty()) o += "<p>" + html(it.description) + "</p>\n";
  if (!it.error.empty()) {
    o += "<p class=\"error\">" + html(it.error) + "</p>\n</main>\n</body>\n</html>\n";
    return o;
  }
  std::string stages;
  for (size_t i = 0; i < it.stages.size(); ++i) stages += (i ? ", " : "") + std::to_string(it.stages[i]);
  const std::string stageWord = it.kind == "shell" ? "ages (degrees)" : it.kind == "tree" ? "steps" : "stages";
  o += "<figure><a href=\"../" + html(it.preview) + "\"><img src=\"../" + html(it.preview) + "\" alt=\"" + html(it.name) +
       ", final stage\"></a><figcaption>The final stage (" + html(it.mode) + " render).</figcaption></figure>\n";
  if (!it.strip.empty())
    o += "<figure><a href=\"../" + html(it.strip) + "\"><img src=\"../" + html(it.strip) + "\" alt=\"" + html(it.name) +
         ", growth stages\"></a><figcaption>Growth strip: " + stageWord + " " + html(stages) + ".</figcaption></figure>\n";
  if (!it.animation.empty())
    o += "<figure><a href=\"../" + html(it.animation) + "\"><img src=\"../" + html(it.animation) + "\" alt=\"" +
         html(it.name) + " growing\"></a><figcaption>Animation, " + std::to_string(it.frames) +
         " frames; it opens on the grown form.</figcaption></figure>\n";
  o += "<table class=\"figs\">\n<tr><td>source</td><td>" + html(it.source) + "</td></tr>\n<tr><td>kind</td><td>" +
       html(it.kind) + "</td></tr>\n";
  if (!set.empty()) o += "<tr><td>figure set</td><td>" + html(set) + "</td></tr>\n";
  o += "<tr><td>render mode</td><td>" + html(it.mode) + "</td></tr>\n<tr><td>steps</td><td>" + std::to_string(it.steps) +
       "</td></tr>\n<tr><td>modules</td><td>" + std::to_string(it.modules) + "</td></tr>\n<tr><td>internodes</td><td>" +
       std::to_string(it.internodes) + "</td></tr>\n<tr><td>primitives</td><td>" + std::to_string(it.primitives) +
       "</td></tr>\n<tr><td>triangles</td><td>" + std::to_string(it.triangles) +
       "</td></tr>\n<tr><td>build</td><td class=\"time\">" + fixed(it.deriveSeconds, 3) +
       " s</td></tr>\n<tr><td>render</td><td class=\"time\">" + fixed(it.renderSeconds, 2) +
       " s</td></tr>\n<tr><td>" + stageWord + "</td><td>" + html(stages) + "</td></tr>\n</table>\n</main>\n</body>\n</html>\n";
  return o;
}

}  // namespace sprig
