#include "model/animate.h"

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

#include "model/model.h"
#include "core/atomic_file.h"
#include "core/diagnostics.h"
#include "core/paths.h"
#include "core/phases.h"
#include "core/progress.h"
#include "render/renderer.h"

extern char** environ;

namespace sprig {

namespace fs = std::filesystem;

AnimationFormat animationFormatFor(const fs::path& out) {
  const std::string ext = lowerExtension(out);
  if (ext.empty() || fs::is_directory(out)) return AnimationFormat::Frames;
  if (ext == ".gif") return AnimationFormat::Gif;
  if (ext == ".mp4") return AnimationFormat::Mp4;
  throw std::invalid_argument("-o " + out.string() + ": unknown animation extension '" + ext +
                              "' (use a folder for PNG frames, .gif or .mp4)");
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

namespace {

/// The output format, after checking that it can be written and the options are sane.
AnimationFormat checkAnimation(const fs::path& out, const AnimateOptions& options, fs::path& ffmpeg) {
  const AnimationFormat format = animationFormatFor(out);
  if (format == AnimationFormat::Mp4) {
    ffmpeg = findFfmpeg();
    if (ffmpeg.empty())
      throw InputError(SourceLoc{out.string()},
                       "cannot write MP4: the ffmpeg command is not installed (install ffmpeg, or write a .gif or a "
                       "folder of PNG frames)");
  }
  if (options.framesPerStage < 1) throw std::invalid_argument("--frames-per-stage must be at least 1");
  if (!(options.fps > 0)) throw std::invalid_argument("--fps must be positive");
  if (!(options.windSpeed >= 0) || !std::isfinite(options.windSpeed) || !std::isfinite(options.windDirectionDeg) ||
      !(options.windSeconds >= 0) || !std::isfinite(options.windSeconds))
    throw std::invalid_argument("--wind: the speed and duration must be finite and not negative");
  return format;
}

}  // namespace

AnimateResult animateSpecies(const Species& species, const fs::path& out, const AnimateOptions& options) {
  fs::path ffmpeg;
  checkAnimation(out, options, ffmpeg);
  SpeciesModel model(species, options.extra, options.lastStage);
  return animateModel(model, species.render, out, options);
}

std::vector<Stage> animationStages(SpeciesModel& model, const AnimateOptions& options, AnimateResult& result) {
  result.lastStage = std::max(0, model.finalStage().step);
  // A tree is derived only up to options.lastStage already; a solid's operation stages are
  // all there, so --stages A..B cuts the sequence here.
  if (options.lastStage >= 0) result.lastStage = std::min(result.lastStage, options.lastStage);
  result.firstStage = std::clamp(options.firstStage, 0, result.lastStage);
  std::vector<Stage> frames = model.animationFrames(options.framesPerStage, result.firstStage, result.lastStage);
  if (options.windSpeed > 0 && !frames.empty()) {
    const auto windFrames = static_cast<size_t>(std::lround(std::max(0.0, options.windSeconds) * options.fps));
    while (frames.size() < windFrames) frames.push_back(frames.back());
    for (size_t i = 0; i < frames.size(); ++i) {
      frames[i].windSpeed = options.windSpeed;
      frames[i].windDirectionDeg = options.windDirectionDeg;
      frames[i].windSeconds = static_cast<double>(i) / options.fps;
    }
  }
  result.frames = static_cast<int>(frames.size());
  return frames;
}

AnimateResult animateModel(SpeciesModel& model, const SpeciesRender& baseLook, const fs::path& out,
                           const AnimateOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  fs::path ffmpeg;
  const AnimationFormat format = checkAnimation(out, options, ffmpeg);
  AnimateResult result;
  const std::vector<Stage> frames = animationStages(model, options, result);
  const GeometryMode mode = options.mode ? *options.mode : model.defaultMode();

  SpeciesRender look = baseLook;
  if (options.samples > 0) look.image.spp = options.samples;
  const int width = options.width > 0 ? options.width : look.image.width;
  const int height = options.height > 0 ? options.height : look.image.height;

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
    FrameSequence sequence(model);  // a frame of the same stage as the one before reuses it
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
      Image img = sequence.render(look, job);
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
    if (options.holdFirst && hold > 0)  // the grown form opens the loop: viewers show frame 0 before playing
      gifFrames.insert(gifFrames.begin(), hold, gifFrames.back());
    else
      for (size_t i = 0; i < hold; ++i) gifFrames.push_back(gifFrames.back());
    const Phase phase("write");
    writeAnimatedGif(gifFrames, options.fps, out);
  }
  if (format == AnimationFormat::Mp4)
    for (size_t i = 0; i < hold; ++i)
      fs::copy_file(frameFolder / frameName(frames.size() - 1), frameFolder / frameName(frames.size() + i));
  if (format == AnimationFormat::Mp4) {
    const Phase phase("write");
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
