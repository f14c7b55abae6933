#pragma once
/// One species of any kind as renderable geometry at any growth stage.
///
/// SpeciesModel is the layer between species files and the commands that show them
/// (`sprig render`, `sprig mesh`, `sprig animate`, the gallery). It knows how each kind
/// grows and what it becomes:
///
/// | kind  | stage                                  | geometry                                      |
/// |-------|----------------------------------------|-----------------------------------------------|
/// | tree  | derivation step + growth fraction      | BlobTree wood + leaf mesh (organisms/tree_builder), or the skeleton preview |
/// | shell | age θ_end in degrees (murex paper §3)  | the shell's BlobTree (organisms/shell)        |
/// | blob  | none (one stage)                       | the BlobTree written in the species file      |
///
/// Every stage of a species is framed by one camera (the final stage's box), so strips and
/// animations do not jump. Building is deterministic: the same species, stage and seed
/// give the same geometry, and so the same image bytes, at any thread count.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/species.h"
#include "core/image.h"
#include "core/mesh.h"
#include "lsystem/grammar.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace sprig {

/// How a species' surface enters a scene.
enum class GeometryMode {
  Exact,     ///< implicit surface ray cast exactly (Embree user geometry)
  Mesh,      ///< the polygonized surface as triangles
  Skeleton,  ///< trees only: internodes as tapered curves (the fast preview)
};

/// "exact", "mesh", "skeleton".
const char* geometryModeName(GeometryMode mode);

/// A growth stage. Trees use step and fraction, shells use age; blobs have one stage.
struct Stage {
  int step = -1;        ///< tree: derivation step (-1 = the species' last)
  double fraction = 1;  ///< tree: growth of the modules created in that step, 0..1
  double age = -1;      ///< shell: θ_end in degrees (-1 = the species' age)
};

/// Counts and times of one built stage (the gallery's figures).
struct ModelFigures {
  size_t modules = 0;     ///< tree: modules in the string
  size_t internodes = 0;  ///< tree: drawn segments
  size_t primitives = 0;  ///< BlobTree primitives (skeleton mode: internodes + organs)
  size_t triangles = 0;   ///< triangles in the scene (leaves, meshes, polygon organs)
  size_t cells = 0;       ///< exact mode: surface cells (Embree user primitives)
  double buildSeconds = 0;  ///< derivation, turtle, BlobTree build, compile, polygonization
};

/// A species prepared to be built at any stage. Not thread-safe; not copyable.
class SpeciesModel {
 public:
  /// Reads what the species' kind needs (the grammar with `extra` overrides on top, the
  /// `shell:` section, the `blob:` tree). lastStep limits a tree's derivation (-1 = the
  /// species' steps). Throws InputError for bad input.
  explicit SpeciesModel(const Species& species, const lsystem::GrammarOverrides& extra = {}, int lastStep = -1);
  ~SpeciesModel();
  SpeciesModel(const SpeciesModel&) = delete;
  SpeciesModel& operator=(const SpeciesModel&) = delete;

  const Species& species() const { return species_; }

  /// True when the species says how to build its surface (a tree with a `tree:` section,
  /// every shell and blob). Trees without one are shown as skeleton previews by the gallery.
  bool hasSurfaceSettings() const;

  /// The mode the gallery uses: Exact with surface settings, else Skeleton.
  GeometryMode defaultMode() const { return hasSurfaceSettings() ? GeometryMode::Exact : GeometryMode::Skeleton; }

  /// The final stage (tree: last step, fraction 1; shell: the species' age).
  Stage finalStage() const;

  /// Tree stages from a command line `--stage K`: step K; shell: the age after K whorls
  /// (capped at the species' age). Throws UsageError for K beyond a tree's steps.
  Stage stageFromIndex(int k) const;

  /// Up to count growth stages ending at the final stage (species `stages:` when given).
  std::vector<Stage> stripStages(int count = 5) const;

  /// The frames of a growth animation: trees run steps first..last (-1 = final) with
  /// framesPerStage frames per step (app/animate.h growthFrames); shells grow from their
  /// first stage to the final age in framesPerStage frames per whorl; blobs have one frame.
  std::vector<Stage> animationFrames(int framesPerStage, int first = 0, int last = -1) const;

  /// Short text for a stage: "step 5", "step 5 at 50%", "age 1392°", "".
  std::string stageName(const Stage& stage) const;

  /// The box the camera frames for every stage: the final stage's bounds.
  Box3 frameBox();

  /// Builds stage into scene with mode (Skeleton for a shell or blob is a UsageError).
  /// Adds the species' materials and textures; call on a fresh scene.
  ModelFigures addToScene(render::Scene& scene, const Stage& stage, GeometryMode mode, const SpeciesRender& look);

  /// The stage's surface as one closed triangle mesh (trees: wood and leaves together).
  /// cellSize 0 = automatic. progress shows a bar on a terminal.
  Mesh buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures* figures = nullptr);

  struct Impl;

 private:
  Species species_;
  std::unique_ptr<Impl> impl_;
};

/// What to render.
struct RenderJob {
  int width = 0;   ///< 0 = the species' render width (height keeps its aspect when only one is given)
  int height = 0;  ///< 0 = the species' render height
  int samples = 0;  ///< 0 = the species' samples
  GeometryMode mode = GeometryMode::Exact;
  Stage stage;
  bool progress = true;
  std::string progressLabel = "render";
};

/// Renders one stage of model with look (camera framed on model.frameBox(), or the species'
/// explicit camera). Fills figures and stats when given.
Image renderModel(SpeciesModel& model, const SpeciesRender& look, const RenderJob& job,
                          ModelFigures* figures = nullptr, render::RenderStats* stats = nullptr);

/// The camera for an image of width x height of a model framed on box with look.
render::Camera modelCamera(const SpeciesRender& look, const Box3& box, int width, int height);

}  // namespace sprig
