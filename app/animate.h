#pragma once
/// Growth-stage animation of a tree species (`sprig animate`, docs/GRAMMAR.md "Growth over time").
///
/// A frame is a (stage, fraction) pair: the string after derivation step `stage`, with the
/// modules created in that step drawn grown by `fraction` (TurtleSettings::growthStep).
/// Frames run stage A at full size, then for each later stage k fractions 1/K .. K/K, so
/// stage k's last frame is exactly its full skeleton. GrowthSequence derives once up front
/// to frame the camera on the union of every stage's bounds (one camera for the whole
/// sequence) and to choose each stage's growthStart, then re-derives lazily as frames are
/// asked for; a derivation is deterministic, so a branch of stage 5 is the same branch at
/// stage 6. renderGrowthFrame is the single function that renders any frame: animations
/// and single renders of a (stage, fraction) give the same bytes.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/model.h"
#include "app/species.h"
#include "core/image.h"
#include "lsystem/derive.h"
#include "lsystem/skeleton.h"

namespace sprig {

/// One frame of a growth animation.
struct GrowthFrame {
  int stage = 0;         ///< derivation step
  double fraction = 1;   ///< growth of the modules created in that step, 0..1
};

/// The frames for stages first..last with framesPerStage frames per step (see file comment).
/// Returns {first, 1} followed by (last - first) * framesPerStage frames.
std::vector<GrowthFrame> growthFrames(int first, int last, int framesPerStage);

/// A tree species' derivation seen as a growing plant. Not thread-safe; not copyable.
class GrowthSequence {
 public:
  /// Derives species (with extra overrides on top of its own) up to lastStage (-1 = the
  /// species' steps; clamped to them) to measure every stage. Throws InputError for
  /// grammar and derivation errors, or when the species is not a tree.
  explicit GrowthSequence(const Species& species, int lastStage = -1, const lsystem::GrammarOverrides& extra = {});
  ~GrowthSequence();
  GrowthSequence(const GrowthSequence&) = delete;
  GrowthSequence& operator=(const GrowthSequence&) = delete;

  /// The last stage (derivation steps) of the sequence.
  int lastStage() const { return lastStage_; }
  /// Union of the full skeletons' bounds over stages 0..lastStage (what the camera frames).
  const DBox3& frameBox() const { return frameBox_; }
  /// Scale of stage k's new modules at fraction 0: chosen so that the total internode
  /// length is continuous from stage k-1 (full) to stage k (fraction 0), clamped to [0, 1].
  /// 0 for grammars that keep old modules (node rewriting: new organs grow from nothing);
  /// 1/2 for F -> FF, whose modules are all new in every step.
  double growthStart(int stage) const;
  /// Modules in the string after step `stage`.
  size_t modulesAt(int stage);
  /// The skeleton of (stage, fraction). Cost: a derivation up to stage when an earlier
  /// stage than the last one asked for is wanted, plus one turtle pass.
  lsystem::Skeleton skeletonAt(int stage, double fraction);

 private:
  void advanceTo(int stage);

  std::unique_ptr<lsystem::Grammar> grammar_;
  std::unique_ptr<lsystem::Deriver> deriver_;
  lsystem::TurtleSettings turtle_;
  int lastStage_ = 0;
  DBox3 frameBox_;
  std::vector<double> start_;  ///< growthStart per stage
  lsystem::ModuleString interpreted_;  ///< the interpreted string of stage interpretedStage_
  int interpretedStage_ = -1;
};

/// Renders frame (stage, fraction) of seq with the species' look, the camera framed on
/// seq.frameBox(); no progress bar. Used by `sprig animate` and the gallery for every frame.
Image renderGrowthFrame(GrowthSequence& seq, const SpeciesRender& look, const GrowthFrame& frame, int width,
                                int height);

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
  int width = 0;            ///< 0 = the species' render width
  int height = 0;           ///< 0 = the species' render height
  int samples = 0;          ///< camera samples per pixel; 0 = the species' own
  lsystem::GrammarOverrides extra;  ///< -D, --steps, --seed on top of the species
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

/// Counts shown in the gallery for a skeleton.
struct SkeletonFigures {
  size_t primitives = 0;  ///< internodes + organs (what the preview renderer puts in its scene)
  size_t triangles = 0;   ///< triangles of polygon organs (a fan of n - 2 per n-gon)
};

/// The figures of skeleton.
SkeletonFigures skeletonFigures(const lsystem::Skeleton& skeleton);

/// The gallery's growth animation of species as a GIF at out: stages 0..steps, half of
/// width x height, a few frames per stage (draft: about 36 frames in all, 2 samples;
/// final: about 120, the look's samples). Returns the number of frames.
int renderGalleryAnimation(const Species& species, const std::filesystem::path& out, const SpeciesRender& look,
                           int width, int height, bool final);

/// The `ffmpeg` executable on PATH, or empty when there is none.
std::filesystem::path findFfmpeg();

}  // namespace sprig
