#pragma once
/// One species of any kind as renderable geometry at any growth stage.
///
/// SpeciesModel is the layer between species files and the commands that show them
/// (`sprig render`, `sprig mesh`, `sprig animate`, the gallery). It knows how each kind
/// grows and what it becomes:
///
/// | kind  | stage                                  | geometry                                      |
/// |-------|----------------------------------------|-----------------------------------------------|
/// | tree  | derivation step + growth fraction      | BlobTree wood + leaf mesh (organisms/tree_builder), or the skeleton preview (model/tree_kind.h) |
/// | shell | age θ_end in degrees (murex paper §3)  | the shell's BlobTree (model/shell_kind.h)     |
/// | blob  | none (one stage)                       | the BlobTree written in the species file (model/blob_kind.h) |
///
/// Each kind lives in its own file pair behind the KindModel interface (model/kinds.h);
/// SpeciesModel only forwards to it.
///
/// Every stage of a species is framed by one camera (the final stage's box), so strips and
/// animations do not jump. Building is deterministic: the same species, stage and seed
/// give the same geometry, and so the same image bytes, at any thread count.

#include <memory>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "lsystem/grammar.h"
#include "model/kinds.h"
#include "model/species.h"
#include "core/image.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace sprig {

/// A species prepared to be built at any stage: the species and its kind's model.
/// Not thread-safe; not copyable.
class SpeciesModel {
 public:
  /// Makes the kind's model (a tree reads its grammar with options.extra on top, and grows
  /// no further than options.lastStep). Throws InputError for bad input.
  explicit SpeciesModel(const Species& species, const ModelOptions& options = {});
  /// The same with a tree's command-line overrides and last step.
  SpeciesModel(const Species& species, const lsystem::GrammarOverrides& extra, int lastStep = -1);
  ~SpeciesModel();
  SpeciesModel(const SpeciesModel&) = delete;
  SpeciesModel& operator=(const SpeciesModel&) = delete;

  const Species& species() const { return species_; }

  /// True when the species says how to build its surface (a tree with a `tree:` section,
  /// every shell and blob). Trees without one are shown as skeleton previews by the gallery.
  bool hasSurfaceSettings() const { return kind_->hasSurface(); }
  /// The mode the gallery uses: Exact with surface settings, else Skeleton.
  GeometryMode defaultMode() const { return hasSurfaceSettings() ? GeometryMode::Exact : GeometryMode::Skeleton; }

  /// The final stage (tree: last step, fraction 1; shell: the species' age).
  Stage finalStage() const { return kind_->finalStage(); }
  /// The stage of a command line `--stage K` (tree: step K; shell: the age after K whorls,
  /// capped at the species' age). Throws UsageError for K beyond a tree's steps.
  Stage stageFromIndex(int k) const { return kind_->stageFromIndex(k); }
  /// The stage of `--age DEG` (capped at the species' age). Throws UsageError for kinds without age.
  Stage stageAtAge(double ageDeg) const { return kind_->stageAtAge(ageDeg); }
  /// Up to count growth stages ending at the final stage (species `stages:` when given).
  std::vector<Stage> stripStages(int count = 5) const { return kind_->stripStages(count); }
  /// The frames of a growth animation: trees run steps first..last (-1 = final) with
  /// framesPerStage frames per step; shells grow from their first strip stage to the final
  /// age in framesPerStage frames per whorl; blobs have one frame.
  std::vector<Stage> animationFrames(int framesPerStage, int first = 0, int last = -1) const {
    return kind_->animationFrames(framesPerStage, first, last);
  }
  /// Short text for a stage: "step 5", "step 5 at 50%", "age 1392 deg", "".
  std::string stageName(const Stage& stage) const { return kind_->stageName(stage); }
  /// The number the gallery shows for a stage (a step, or an age in degrees).
  int stageNumber(const Stage& stage) const { return kind_->stageNumber(stage); }
  /// The box the camera frames for every stage: the final stage's bounds (trees: the union
  /// over their steps).
  /// The box the camera frames; for a solid this builds it, so the time is the "build" phase.
  Box3 frameBox();
  /// The box of a close-up's target (`render.close_up`): the point itself, or the named
  /// part's box (KindModel::partBox). Throws InputError as partBox does.
  Box3 closeUpBox(const CloseUpSpec& target);
  /// Extensions of the volume meshes the species writes (solids: .msh, .vtu, .mesh).
  std::vector<std::string> volumeMeshExtensions() const { return kind_->volumeMeshExtensions(); }
  /// Writes the stage's volume mesh (KindModel::writeVolumeMesh); returns the summary line.
  std::string writeVolumeMesh(const Stage& stage, const std::filesystem::path& path, bool progress) {
    return kind_->writeVolumeMesh(stage, path, progress);
  }
  /// The interfaces between materials as named meshes (KindModel::interfaceMeshes).
  std::vector<std::pair<std::string, Mesh>> interfaceMeshes(const Stage& stage) { return kind_->interfaceMeshes(stage); }
  /// LOD0's triangle budget of `sprig mesh` by default (KindModel::lodBudget); 0: no levels.
  size_t lodBudget() const { return kind_->lodBudget(); }
  /// How the gallery animates the species.
  GalleryMotion galleryMotion(bool final) { return kind_->galleryMotion(final); }

  /// The stage's geometry with look. Throws UsageError for a mode the kind lacks.
  BuiltStage build(const Stage& stage, GeometryMode mode, const SpeciesRender& look) {
    return kind_->build(stage, mode, look);
  }
  /// Builds stage into scene (a fresh one) with mode; returns its figures.
  ModelFigures addToScene(render::Scene& scene, const Stage& stage, GeometryMode mode, const SpeciesRender& look);

  /// The stage's surface as one closed triangle mesh (trees: wood and leaves together).
  /// cellSize 0 = automatic. progress shows a bar on a terminal.
  Mesh buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures* figures = nullptr);

  /// The final stage's surface as another species takes it (an organism's `base: {species}`,
  /// a solid's `distance_field: {species}`): buildMesh at the automatic cell, then cleaned
  /// as `sprig mesh` cleans a polygonized surface (cleanMesh with clean: the components
  /// below its fraction of the model's volume removed, specks outside and voids inside;
  /// normals made to agree with the winding). report receives what the cleaning did.
  Mesh cleanSurface(const MeshCleanOptions& clean = {}, MeshCleanReport* report = nullptr, ModelFigures* figures = nullptr);

  /// The stage's surface as named parts in the species' colours (KindModel::exportParts),
  /// polygonized BlobTrees cleaned with clean. Fills figures (triangles: all parts', build time).
  /// meshTriangles > 0 (levels of detail, cellSize 0): a tree's wood at the coarser cell
  /// that gives about that many triangles (SpeciesRender::meshTriangles).
  std::vector<ExportPart> exportParts(const Stage& stage, float cellSize, bool progress, const MeshCleanOptions& clean = {},
                                      ModelFigures* figures = nullptr, size_t meshTriangles = 0);
  /// The stage's still skeleton and the species' wind options (KindModel::windSource);
  /// nullopt for kinds without wind.
  std::optional<std::pair<lsystem::Skeleton, organisms::WindOptions>> windSource(const Stage& stage) {
    return kind_->windSource(stage);
  }

 private:
  Species species_;
  std::unique_ptr<KindModel> kind_;
};

/// What to render.
struct RenderJob {
  int width = 0;   ///< 0 = the species' render width (height keeps its aspect when only one is given)
  int height = 0;  ///< 0 = the species' render height
  int samples = 0;  ///< 0 = the species' samples
  GeometryMode mode = GeometryMode::Exact;
  Stage stage;
  std::optional<Box3> frame;  ///< the box the camera frames (default: the model's frameBox())
  /// The camera, used as it is (no close-up, no resting shift); default: speciesCamera's.
  std::optional<render::Camera> camera;
  bool progress = true;
  std::string progressLabel = "render";
  /// Implicit models' surface cells sized for this camera's pixel in an image cellHeight
  /// rows tall instead of the picture's (render::Scene::setCellFootprint; the mesh mode
  /// polygonizes at that pixel too): renderInset's close-up traced in the whole picture's
  /// cells. The same surface, another cost.
  std::optional<render::Camera> cellCamera;
  int cellHeight = 0;
};

/// Most camera rays (width x height x samples per pixel) one image may take: 2^34, about
/// 17 billion (8192 x 8192 at 256 samples), hours of rendering. Raise it here.
inline constexpr uint64_t kMaxCameraRays = uint64_t(1) << 34;

/// Throws UsageError naming the flags and keys to lower when width x height x samples
/// exceeds kMaxCameraRays. Called before anything is built or allocated.
void checkCameraRays(int width, int height, int samples);

/// Renders one stage of model with look (camera framed on model.frameBox(), or the species'
/// explicit camera). Every stage is staged as the frame's: it rests on the ground, and the
/// framed camera moves up or down with its lowest point so that the ground, its fade and the
/// horizon are where the frame's are (the same row in every stage of a strip or animation). Fills figures and stats when given. Throws UsageError (checkCameraRays)
/// for an image over kMaxCameraRays rays; InputError at the species for a framed box that is
/// not finite, reaches beyond render::kMaxRenderCoordinate or has zero size, and for a
/// camera that cannot make valid rays (render::cameraProblem).
Image renderModel(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job,
                          ModelFigures* figures = nullptr, render::RenderStats* stats = nullptr);

struct BuiltScene;

/// Frames of one model seen with one look (apart from look.view, which may turn from frame
/// to frame), each the same bytes as renderModel of the same look and job, with work shared
/// between frames: a frame of the same stage, mode and size as the one before reuses its
/// built, committed scene when that scene serves the frame's camera (render::Scene::
/// servesCamera: triangles, or implicit cells the new camera sizes alike; not the mesh mode,
/// whose polygonization cell follows the pixels, nor a wireframe, whose curve widths do),
/// and its picture when the camera, frame box and samples are the same too. A frame of another stage rebuilds. Used by animateModel and the gallery's
/// turntables. Not thread-safe; the model must outlive it.
class FrameSequence {
 public:
  explicit FrameSequence(SpeciesModel& model);
  ~FrameSequence();
  FrameSequence(const FrameSequence&) = delete;
  FrameSequence& operator=(const FrameSequence&) = delete;

  /// renderModel(model, look, job), reusing what the previous frame built. Throws as renderModel.
  Image render(const SpeciesRender& look, const RenderJob& job);

  int builtScenes() const { return builtScenes_; }    ///< frames that built their scene
  int reusedScenes() const { return reusedScenes_; }  ///< frames rendered from the previous frame's scene
  int reusedImages() const { return reusedImages_; }  ///< frames that were the previous frame's picture

 private:
  SpeciesModel& model_;
  std::unique_ptr<BuiltScene> built_;
  Stage stage_;
  GeometryMode mode_ = GeometryMode::Exact;
  int width_ = 0, height_ = 0, samples_ = 0;
  render::Camera camera_;
  Box3 frame_;
  Image image_;
  int builtScenes_ = 0, reusedScenes_ = 0, reusedImages_ = 0;
};

/// Half the width in pixels of the rule between renderPair's panels: 1, and 1 more for
/// every 512 pixels of a panel's width.
int pairDividerHalfWidth(int panel);

/// The camera both panels of renderPair use for a width x height image (each panel half as
/// wide): speciesCamera of model over the union of model's and other's frame boxes.
render::Camera pairCamera(SpeciesModel& model, SpeciesModel& other, const SpeciesRender& look, int width, int height);

/// Two species side by side (`render.pair`): model at job.stage in the left panel, other at
/// its final stage in the right, each panel half the job's width (at least 16 pixels) and
/// its height, both rendered with look and seen by one camera (job.camera, else pairCamera),
/// each resting on its own ground, which fades around the union of the two frame boxes. A
/// white rule of pairDividerHalfWidth(panel) columns on each side of the seam covers the
/// panels' facing edges, so that each reads as its own picture. Fills figures (model's) and
/// stats (both panels') when given. Throws as renderModel.
Image renderPair(SpeciesModel& model, SpeciesModel& other, const SpeciesRender& look, const RenderJob& job,
                 ModelFigures* figures = nullptr, render::RenderStats* stats = nullptr);

/// Where renderPicture draws look.inset into a width x height picture: the inset's size, its
/// top left corner (the lower right corner of the picture) and the width of the white rule
/// along its top and left edges (2 * pairDividerHalfWidth of the inset's width).
struct InsetPlace {
  int x = 0, y = 0, width = 0, height = 0, rule = 0;
};
InsetPlace insetPlace(const InsetSpec& inset, int width, int height);

/// The inset of look's width x height picture: renderModel of model at job.stage with
/// look.inset->look at insetPlace's size, framed by the inset's own close-up or camera
/// (job.camera and job.frame are not used), its implicit cells sized for the whole
/// picture's camera (RenderJob::cellCamera; job.camera, else the species' framing).
/// Throws as renderModel.
Image renderInset(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job, int width, int height,
                  render::RenderStats* stats = nullptr);

/// The species' picture, as `sprig render` and the gallery's final stage show it: with
/// look.pair, renderPair with that species (loaded under the model's species' path policy;
/// its own `pair` is not followed); else renderModel. With look.inset, renderInset drawn
/// over the lower right corner (insetPlace) of either. Throws InputError for the other
/// species' errors too.
Image renderPicture(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job, ModelFigures* figures = nullptr,
                    render::RenderStats* stats = nullptr);

/// The frame box moved up or down so that its base is the stage's lowest point: the stage
/// rests on the ground, and a camera framed on the result sees that ground from where the
/// frame's camera sees the frame's (one horizon row for every stage). frame itself when the
/// stage box is empty or not finite, or the ground is not at the model's base.
Box3 restingFrame(const Box3& frame, const Box3& stage, bool groundAtModelBase);

/// The camera for an image of width x height of a model framed on box with look.
render::Camera modelCamera(const SpeciesRender& look, const Box3& box, int width, int height);

/// The camera renderModel takes for model in a width x height image framed on frame: with a
/// close-up (render.close_up), looking along look.view at the target (model.closeUpBox),
/// either framing its box with the view's margin or, with a size, at the distance where a
/// square of that side across the view fills the frame's shorter side less the margin;
/// else modelCamera's. Throws InputError as closeUpBox does.
render::Camera speciesCamera(SpeciesModel& model, const SpeciesRender& look, const Box3& frame, int width, int height);

}  // namespace sprig
