#include "app/animate.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>

#include "app/model.h"
#include "app/preview.h"
#include "core/atomic_file.h"
#include "core/diagnostics.h"
#include "core/paths.h"
#include "core/progress.h"
#include "lsystem/turtle.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"

extern char** environ;

namespace sprig {

namespace fs = std::filesystem;

std::vector<GrowthFrame> growthFrames(int first, int last, int framesPerStage) {
  std::vector<GrowthFrame> frames;
  frames.push_back({first, 1.0});
  const int k = std::max(framesPerStage, 1);
  for (int stage = first + 1; stage <= last; ++stage)
    for (int j = 1; j <= k; ++j) frames.push_back({stage, static_cast<double>(j) / k});
  return frames;
}

GrowthSequence::GrowthSequence(const Species& species, int lastStage, const lsystem::GrammarOverrides& extra) {
  if (species.kind != SpeciesKind::Tree)
    throw InputError(SourceLoc{species.file.string()},
                     std::string("only tree species grow from a grammar; this one is ") + speciesKindName(species.kind));
  grammar_ = std::make_unique<lsystem::Grammar>(speciesGrammar(species, extra));
  lsystem::DeriveOptions dopt;
  dopt.maxModules = species.maxModules;
  dopt.trackBirthSteps = true;
  deriver_ = std::make_unique<lsystem::Deriver>(*grammar_, dopt);
  turtle_ = speciesTurtle(species, *grammar_);
  lastStage_ = lastStage < 0 ? deriver_->steps() : std::min(lastStage, deriver_->steps());

  // One pass over every stage: the camera's box, and each stage's growthStart from the
  // internode lengths (old modules, new modules) against the previous stage's total.
  start_.assign(static_cast<size_t>(lastStage_) + 1, 0.0);
  double previousLength = 0;
  for (int stage = 0; stage <= lastStage_; ++stage) {
    if (ProgressSettings::cancelRequested()) throw Cancelled();
    if (stage > 0) deriver_->step();
    lsystem::ModuleString s = deriver_->interpret(deriver_->current());
    lsystem::Skeleton sk = lsystem::Turtle(deriver_->symbols(), turtle_).run(s, s.birthSteps);
    const DBox3 b = framingBox(sk);
    frameBox_ = stage == 0 ? b : DBox3{glm::min(frameBox_.lo, b.lo), glm::max(frameBox_.hi, b.hi)};
    double oldLength = 0, newLength = 0;
    for (const auto& in : sk.internodes) (in.step < stage ? oldLength : newLength) += in.length();
    if (stage > 0 && newLength > 0) start_[stage] = std::clamp((previousLength - oldLength) / newLength, 0.0, 1.0);
    previousLength = oldLength + newLength;
    interpreted_ = std::move(s);
    interpretedStage_ = stage;
  }
}

GrowthSequence::~GrowthSequence() = default;

double GrowthSequence::growthStart(int stage) const {
  return stage >= 0 && stage <= lastStage_ ? start_[static_cast<size_t>(stage)] : 0.0;
}

void GrowthSequence::advanceTo(int stage) {
  if (stage < 0 || stage > lastStage_)
    throw std::invalid_argument("stage " + std::to_string(stage) + " is outside 0.." + std::to_string(lastStage_));
  if (interpretedStage_ == stage) return;
  if (deriver_->stepsDone() > stage) deriver_->restart();
  while (deriver_->stepsDone() < stage) {
    if (ProgressSettings::cancelRequested()) throw Cancelled();
    deriver_->step();
  }
  interpreted_ = deriver_->interpret(deriver_->current());
  interpretedStage_ = stage;
}

size_t GrowthSequence::modulesAt(int stage) {
  advanceTo(stage);
  return deriver_->current().size();
}

lsystem::Skeleton GrowthSequence::skeletonAt(int stage, double fraction) {
  advanceTo(stage);
  lsystem::TurtleSettings ts = turtle_;
  ts.growthStep = stage;
  ts.growthFraction = fraction;
  ts.growthStart = growthStart(stage);
  return lsystem::Turtle(deriver_->symbols(), ts).run(interpreted_, interpreted_.birthSteps);
}

Image renderGrowthFrame(GrowthSequence& seq, const SpeciesRender& look, const GrowthFrame& frame, int width,
                                int height) {
  lsystem::Skeleton sk = seq.skeletonAt(frame.stage, frame.fraction);
  render::Scene scene;
  scene.addSkeleton(sk, look.style);
  scene.commit();
  const DBox3& fb = seq.frameBox();
  render::Camera camera =
      render::frameBounds(Box3{Vec3(fb.lo), Vec3(fb.hi)}, look.view, static_cast<double>(width) / height);
  render::RenderSettings rs = look.settings(width, height);
  rs.progress = false;
  return render::renderImage(scene, camera, rs);
}

AnimationFormat animationFormatFor(const fs::path& out) {
  const std::string ext = lowerExtension(out);
  if (ext.empty() || fs::is_directory(out)) return AnimationFormat::Frames;
  if (ext == ".gif") return AnimationFormat::Gif;
  if (ext == ".mp4") return AnimationFormat::Mp4;
  throw std::invalid_argument("-o " + out.string() + ": unknown animation extension '" + ext +
                              "' (use a folder for PNG frames, .gif or .mp4)");
}

SkeletonFigures skeletonFigures(const lsystem::Skeleton& skeleton) {
  SkeletonFigures f;
  f.primitives = skeleton.internodes.size() + skeleton.organs.size();
  for (const auto& o : skeleton.organs)
    if (o.kind == lsystem::Organ::Kind::Polygon && o.points.size() >= 3) f.triangles += o.points.size() - 2;
  return f;
}

int renderGalleryAnimation(const Species& species, const fs::path& out, const SpeciesRender& look, int width,
                           int height, bool final) {
  Species shown = species;
  shown.render = look;
  const int w = std::max(16, width / 2), h = std::max(16, height / 2);
  const bool exact = species.kind != SpeciesKind::Tree || species.treeSection.has_value();
  const int samples = final ? look.samples : std::min(look.samples, exact ? 1 : 2);
  if (species.kind == SpeciesKind::Blob) {
    // A blob does not grow: a turntable around it instead, one camera distance throughout.
    SpeciesModel model(shown);
    const int n = final ? 48 : 8;
    std::vector<Image> frames;
    Progress bar("turntable " + species.name, static_cast<size_t>(n));
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
  if (species.kind == SpeciesKind::Shell) {
    opt.framesPerStage = final ? 6 : 1;  // per whorl
  } else {
    GrowthSequence probe(species);
    const int steps = std::max(1, probe.lastStage());
    // Exact frames rebuild the BlobTree each time: drafts show one frame per step.
    opt.framesPerStage = exact && !final ? 1 : std::clamp((final ? 120 : 36) / steps, 1, final ? 8 : 4);
  }
  opt.fps = final ? 12 : 8;
  opt.holdSeconds = 1;
  opt.width = w;
  opt.height = h;
  opt.samples = samples;
  opt.progressLabel = "animate " + species.name;
  return animateSpecies(shown, out, opt).frames;
}

fs::path findFfmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return {};
  std::string p = path;
  size_t begin = 0;
  while (begin <= p.size()) {
    size_t end = p.find(':', begin);
    if (end == std::string::npos) end = p.size();
    fs::path candidate = fs::path(p.substr(begin, end - begin).empty() ? "." : p.substr(begin, end - begin)) / "ffmpeg";
    if (::access(candidate.c_str(), X_OK) == 0 && fs::is_regular_file(candidate)) return candidate;
    begin = end + 1;
  }
  return {};
}

namespace {

std::string frameName(size_t i) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "frame_%05zu.png", i);
  return buf;
}

/// Runs argv (argv[0] a full path) and returns its exit status (-1 when it did not run).
int runProgram(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// A private folder under the system temp folder, removed with everything in it.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (fs::temp_directory_path() / "sprig-frames-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary folder for MP4 frames");
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

AnimateResult animateSpecies(const Species& species, const fs::path& out, const AnimateOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const AnimationFormat format = animationFormatFor(out);
  fs::path ffmpeg;
  if (format == AnimationFormat::Mp4) {
    ffmpeg = findFfmpeg();
    if (ffmpeg.empty())
      throw InputError(SourceLoc{out.string()},
                       "cannot write MP4: the ffmpeg command is not installed (install ffmpeg, or write a .gif or a "
                       "folder of PNG frames)");
  }
  if (options.framesPerStage < 1) throw std::invalid_argument("--frames-per-stage must be at least 1");
  if (!(options.fps > 0)) throw std::invalid_argument("--fps must be positive");

  SpeciesModel model(species, options.extra, options.lastStage);
  AnimateResult result;
  result.lastStage = std::max(0, model.finalStage().step);
  result.firstStage = std::clamp(options.firstStage, 0, result.lastStage);
  const std::vector<Stage> frames = model.animationFrames(options.framesPerStage, result.firstStage, result.lastStage);
  result.frames = static_cast<int>(frames.size());
  const GeometryMode mode = options.mode ? *options.mode : model.defaultMode();

  SpeciesRender look = species.render;
  if (options.samples > 0) look.samples = options.samples;
  const int width = options.width > 0 ? options.width : look.width;
  const int height = options.height > 0 ? options.height : look.height;

  std::optional<TempFolder> mp4Frames;
  fs::path frameFolder = out;
  if (format == AnimationFormat::Frames) {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (!fs::is_directory(out)) throw std::runtime_error("-o " + out.string() + ": cannot create the frame folder");
    removeStaleTemporaries(out);
  } else if (format == AnimationFormat::Mp4) {
    mp4Frames.emplace();
    frameFolder = mp4Frames->path();
  }

  std::vector<Image> gifFrames;
  {
    std::optional<Progress> bar;
    if (!options.progressLabel.empty()) bar.emplace(options.progressLabel, frames.size());
    for (size_t i = 0; i < frames.size(); ++i) {
      if (ProgressSettings::cancelRequested()) throw Cancelled();
      RenderJob job;
      job.width = width;
      job.height = height;
      job.mode = mode;
      job.stage = frames[i];
      job.progress = false;
      Image img = renderModel(model, look, job);
      if (format == AnimationFormat::Gif)
        gifFrames.push_back(std::move(img));
      else
        writeImage(img, frameFolder / frameName(i));
      if (bar) bar->advance();
    }
    if (bar) bar->finish();
  }

  // The hold: the last frame repeated (GIF and MP4 have no per-frame duration here).
  const size_t hold = format == AnimationFormat::Frames
                          ? 0
                          : static_cast<size_t>(std::lround(std::max(0.0, options.holdSeconds) * options.fps));
  if (format == AnimationFormat::Gif) {
    for (size_t i = 0; i < hold; ++i) gifFrames.push_back(gifFrames.back());
    writeAnimatedGif(gifFrames, options.fps, out);
  }
  if (format == AnimationFormat::Mp4)
    for (size_t i = 0; i < hold; ++i)
      fs::copy_file(frameFolder / frameName(frames.size() - 1), frameFolder / frameName(frames.size() + i));
  if (format == AnimationFormat::Mp4) {
    TempPath tmp(out);
    char rate[32];
    std::snprintf(rate, sizeof rate, "%g", options.fps);
    const int rc = runProgram({ffmpeg.string(), "-y", "-loglevel", "error", "-framerate", rate, "-i",
                               (frameFolder / "frame_%05d.png").string(), "-c:v", "libx264", "-pix_fmt", "yuv420p",
                               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", tmp.path().string()});
    if (rc != 0) throw std::runtime_error(out.string() + ": ffmpeg failed (exit status " + std::to_string(rc) + ")");
    tmp.commit();
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace sprig
