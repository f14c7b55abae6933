#pragma once
/// Growth animation of any species (`sprig animate`, docs/GRAMMAR.md "Growth over time"):
/// the frames of SpeciesModel::animationFrames (trees grow step by step, shells whorl by
/// whorl), each rendered by renderModel, so an animation frame and a single render of the
/// same stage give the same bytes.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "lsystem/grammar.h"
#include "model/model.h"
#include "model/species.h"
#include "core/image.h"

namespace sprig {

/// What `sprig animate` writes.
enum class AnimationFormat { Frames, Gif, Mp4 };

/// Frames for a path without extension or an existing folder, Gif for .gif, Mp4 for .mp4.
/// Throws std::invalid_argument for any other extension.
AnimationFormat animationFormatFor(const std::filesystem::path& out);

/// Options of animateSpecies.
struct AnimateOptions {
  int firstStage = 0;       ///< first stage shown (at full size)
  int lastStage = -1;       ///< -1 = the species' steps
  int framesPerStage = 6;   ///< frames over which one step's new modules grow in
  double fps = 12;          ///< GIF and MP4 frame rate
  double holdSeconds = 0;   ///< GIF and MP4: show the last frame this much longer before looping
  /// GIF: the hold comes first instead of last, so the file's first frame (what a page or
  /// file browser shows before the animation plays) is the grown form, not the sprout.
  bool holdFirst = false;
  int width = 0;            ///< 0 = the species' render width
  int height = 0;           ///< 0 = the species' render height
  int samples = 0;          ///< camera samples per pixel; 0 = the species' own
  lsystem::GrammarOverrides extra;  ///< -D, --steps, --seed on top of the species
  /// Wind (trees only, organisms/wind.h): speed in m/s (0 = none) and the azimuth it blows
  /// toward. Frame i sways at time i / fps; with wind the animation lasts at least
  /// windSeconds, holding the last stage while the wind blows on.
  double windSpeed = 0;
  double windDirectionDeg = 0;
  double windSeconds = 4;
  std::string progressLabel = "animate";  ///< empty = no progress bar
  /// How frames show the species; unset = SpeciesModel::defaultMode() (exact surfaces for
  /// trees with a `tree:` section, shells and blobs; skeleton previews for other trees).
  std::optional<GeometryMode> mode;
};

/// What animateSpecies did.
struct AnimateResult {
  int frames = 0;
  int firstStage = 0;
  int lastStage = 0;
  double seconds = 0;
};

/// Renders the growth of species to out (frames from SpeciesModel::animationFrames: trees
/// grow step by step, shells whorl by whorl, each frame through renderModel) (format from animationFormatFor): a folder of
/// frame_NNNNN.png (each frame written atomically), or an animated GIF / MP4 renamed into
/// place only when complete. MP4 needs the `ffmpeg` command. Throws InputError for bad
/// species or a missing ffmpeg, std::invalid_argument for bad options, Cancelled on a signal.
AnimateResult animateSpecies(const Species& species, const std::filesystem::path& out, const AnimateOptions& options);

/// animateSpecies for a model already built (its extra overrides and last stage are the
/// model's; options.extra and lastStage are not read again), shown with look.
AnimateResult animateModel(SpeciesModel& model, const SpeciesRender& look, const std::filesystem::path& out,
                           const AnimateOptions& options);

/// The stages animateModel renders, in order (its frames, wind included), for model and
/// options; result receives the first and last stage shown and the frame count. Used by
/// programs that render the frames themselves (the Python module's Species.animate).
std::vector<Stage> animationStages(SpeciesModel& model, const AnimateOptions& options, AnimateResult& result);

/// The `ffmpeg` executable on PATH, or empty when there is none.
std::filesystem::path findFfmpeg();

}  // namespace sprig
