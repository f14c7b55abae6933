#pragma once
/// The species kinds: the one interface each kind provides, and the registry of kinds.
///
/// A kind lives in one file pair (model/<kind>_kind.{h,cpp}) and provides:
/// - a typed value of its keys (a KindSpec), read completely when the species is loaded;
/// - a KindModel: its stages, the box its camera frames, and build(stage) -> neutral
///   geometry (render/geometry.h) or a mesh.
/// Commands, animation and the gallery see only these interfaces (through SpeciesModel,
/// model/model.h), never a test of the kind. Adding a kind is a file pair and one line in
/// the registry (model/kinds.cpp); docs/DEVELOPERS.md "Adding a species kind" is the recipe.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "core/mesh_clean.h"
#include "core/mesh_io.h"
#include "core/types.h"
#include "lsystem/grammar.h"
#include "lsystem/skeleton.h"
#include "model/species.h"
#include "organisms/wind.h"
#include "model/yaml_reader.h"
#include "render/geometry.h"

namespace sprig {

/// How a species' surface is built.
enum class GeometryMode {
  Exact,     ///< implicit surface ray cast exactly (Embree user geometry)
  Mesh,      ///< the polygonized surface as triangles
  Skeleton,  ///< trees only: internodes as tapered curves (the fast preview)
};

/// "exact", "mesh", "skeleton".
const char* geometryModeName(GeometryMode mode);
/// The mode named "exact", "mesh" or "skeleton"; throws UsageError for any other name.
GeometryMode geometryModeNamed(const std::string& name);

/// A growth stage. Trees use step and fraction, shells use age, organisms time; blobs have one stage.
struct Stage {
  int step = -1;        ///< tree: derivation step (-1 = the species' last)
  double fraction = 1;  ///< tree: growth of the modules created in that step, 0..1
  double age = -1;      ///< shell: θ_end in degrees (-1 = the species' age)
  double time = -1;     ///< organism: animation time 0..1 (-1 = the final time, 1)
  double windSpeed = 0;         ///< tree: wind speed, m/s (0 = still; organisms/wind.h)
  double windDirectionDeg = 0;  ///< tree: azimuth the wind blows toward
  double windSeconds = 0;       ///< tree: the moment of the wind's sway, seconds
};

/// Counts and times of one built stage (the gallery's figures).
struct ModelFigures {
  size_t modules = 0;     ///< tree: modules in the string
  size_t internodes = 0;  ///< tree: drawn segments
  size_t primitives = 0;  ///< BlobTree primitives (skeleton mode: internodes + organs)
  size_t triangles = 0;   ///< triangles in the scene (leaves, meshes, polygon organs)
  size_t cells = 0;       ///< exact mode: surface cells (Embree user primitives)
  double buildSeconds = 0;  ///< derivation, turtle, BlobTree build, compile, polygonization
  /// exportParts: what cleaning the polygonized wood or shell found (zero when nothing was cleaned).
  MeshCleanReport clean;
  /// exportParts of a tree at SpeciesRender::meshTriangles: the automatic cell, the
  /// coarsest one allowed (lodCellCeiling) and the one the wood was polygonized at
  /// (lodCellSize); 0 otherwise.
  float autoCell = 0.0f, ceilingCell = 0.0f, lodCell = 0.0f;
};

/// A built stage: what to render, and its figures.
struct BuiltStage {
  render::Geometry geometry;
  ModelFigures figures;
};

/// How the gallery animates a kind.
struct GalleryMotion {
  bool turntable = false;  ///< orbit the camera around the one stage instead of growing
  int framesPerStage = 1;  ///< growth frames per stage (trees: per step, shells: per whorl)
};

/// Options of a model beyond its species.
struct ModelOptions {
  lsystem::GrammarOverrides extra;  ///< trees: command-line -D, --steps, --seed
  int lastStep = -1;                ///< trees: stop after this step (-1 = the species' steps)
};

/// One species of some kind, ready to be built at any stage. Not thread-safe.
class KindModel {
 public:
  virtual ~KindModel() = default;

  /// True when the species says how to build its surface (Exact and Mesh modes work); trees
  /// without a `tree:` section are shown as skeleton previews.
  virtual bool hasSurface() const = 0;
  /// The final stage (tree: last step, fraction 1; shell: the species' age).
  virtual Stage finalStage() const = 0;
  /// The stage of a command line `--stage K`. Throws UsageError when there is none.
  virtual Stage stageFromIndex(int k) const = 0;
  /// The stage of a command line `--age DEG`. Throws UsageError for kinds without an age.
  virtual Stage stageAtAge(double ageDeg) const;
  /// Up to count growth stages ending at the final stage; at least one (the final stage).
  virtual std::vector<Stage> stripStages(int count) const = 0;
  /// The frames of a growth animation between stages first and last (-1 = final).
  virtual std::vector<Stage> animationFrames(int framesPerStage, int first, int last) const = 0;
  /// Short text for a stage: "step 5", "step 5 at 50%", "age 1392 deg", "".
  virtual std::string stageName(const Stage& stage) const = 0;
  /// The number the gallery shows for a stage (a step, or an age in degrees).
  virtual int stageNumber(const Stage& stage) const = 0;
  /// The box the camera frames for every stage.
  virtual Box3 frameBox() = 0;
  /// The world box of the part a close-up names (`render.close_up`'s `internode` or
  /// `junction`) in the final stage. Throws InputError at target.loc when the part does not
  /// exist; the default throws that the kind has no named parts.
  virtual Box3 partBox(const CloseUpSpec& target);
  /// The stage's geometry with the species' look. Throws UsageError for a mode the kind
  /// lacks, InputError for bad input found while building.
  virtual BuiltStage build(const Stage& stage, GeometryMode mode, const SpeciesRender& look) = 0;
  /// The stage's surface as one closed triangle mesh; cellSize 0 = automatic.
  virtual Mesh buildMesh(const Stage& stage, float cellSize, bool progress, ModelFigures& figures) = 0;
  /// The stage's surface as named parts with the species' colours, for `sprig mesh`
  /// (core/mesh_io.h writeParts): trees wood, leaves, fruit; shells whorl, varices, spines,
  /// bumps, inside; solids one part per material; others one part. Polygonized BlobTrees are
  /// cleaned (core/mesh_clean.h) with clean, the report in figures.clean. The default is
  /// buildMesh as one part "surface" in look.surface's colour.
  virtual std::vector<ExportPart> exportParts(const Stage& stage, float cellSize, bool progress, const SpeciesRender& look,
                                              const MeshCleanOptions& clean, ModelFigures& figures);
  /// Trees: the stage's still skeleton (the one exportParts builds from) and the wind's
  /// options of the species (seed; speed and direction from its `render: wind`), for the wind data
  /// of a glTF export (model/wind_export.h). nullopt (the default): the kind has no wind.
  virtual std::optional<std::pair<lsystem::Skeleton, organisms::WindOptions>> windSource(const Stage&) { return std::nullopt; }
  /// The triangle budget of LOD0 when `sprig mesh` writes levels of detail by default
  /// (model/lod.h; docs/MESHES.md "Levels of detail"); 0 (the default): the full mesh alone.
  virtual size_t lodBudget() const { return 0; }
  /// How the gallery animates it.
  virtual GalleryMotion galleryMotion(bool final) = 0;
  /// Extensions of the volume (tetrahedral) meshes the kind writes (".msh", ...); empty
  /// (the default) for kinds that have only a surface.
  virtual std::vector<std::string> volumeMeshExtensions() const { return {}; }
  /// Writes the stage's volume mesh to path (its extension one of volumeMeshExtensions())
  /// atomically and returns the line `sprig mesh` prints. The default throws UsageError.
  virtual std::string writeVolumeMesh(const Stage& stage, const std::filesystem::path& path, bool progress);
  /// The stage's interfaces between materials as meshes, each with its name ("nut_chocolate",
  /// "foil_outside"). The default throws UsageError (only solids have materials).
  virtual std::vector<std::pair<std::string, Mesh>> interfaceMeshes(const Stage& stage);
};

/// A species with one stage that does not grow (blobs, solids): every stage is that one, and
/// the gallery turns the camera around it.
class StillKindModel : public KindModel {
 public:
  bool hasSurface() const override { return true; }
  Stage finalStage() const override { return {}; }
  Stage stageFromIndex(int) const override { return {}; }
  std::vector<Stage> stripStages(int) const override { return {Stage{}}; }
  std::vector<Stage> animationFrames(int, int, int) const override { return {Stage{}}; }
  std::string stageName(const Stage&) const override { return {}; }
  int stageNumber(const Stage& stage) const override { return stage.step; }
  GalleryMotion galleryMotion(bool) override {
    GalleryMotion m;
    m.turntable = true;
    return m;
  }
};

/// A kind's keys, read and typed (one subclass per kind).
class KindSpec {
 public:
  virtual ~KindSpec() = default;
  /// What `sprig check` prints for a good file after "KIND species 'NAME'" (", 3 productions, 10 steps").
  /// May build the final stage to surface builder errors; throws InputError.
  virtual std::string checkSummary(const Species& species) const = 0;
  /// A model of species (whose spec is this).
  virtual std::unique_ptr<KindModel> makeModel(const Species& species, const ModelOptions& options) const = 0;
};

/// A kind in the registry: its `kind:` name and the reader of its keys, which reads them from
/// the top-level map into a KindSpec (adding every error to diags; may return null then).
struct KindEntry {
  const char* name;
  std::shared_ptr<const KindSpec> (*read)(MapReader& top, Species& species, DiagnosticList& diags);
};

/// The registered kinds, in the order error messages list them.
const std::vector<KindEntry>& speciesKinds();

/// The registered kind named name, or null.
const KindEntry* findKind(const std::string& name);

}  // namespace sprig
