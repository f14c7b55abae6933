#pragma once
/// Species files (`species/*.yaml`) and bare grammars as the input of every `sprig` command.
///
/// A species file names its kind and holds everything needed to grow and show one
/// organism; README.md ("Species files") lists every key with its default. For `kind: tree`
/// the file names a grammar (a path relative to the species file, or inline text with
/// `grammar: |`), overrides of its `#define` constants, derivation steps and seed,
/// turtle settings, render settings and growth stages. Sections that other parts of
/// Sprig own (`tree:` for the BlobTree tree builder, `shell:`, the blob keys) are kept as
/// raw YAML nodes and read by their own readers.
///
/// A bare `.lsys` file is a species with default settings whose grammar is that file.
///
/// Every error of a species file is collected and thrown as one InputError with
/// `file:line:col` positions; inline grammars report positions inside the species file.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/yaml_reader.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"

namespace sprig {

/// What a species file describes.
enum class SpeciesKind { Tree, Shell, Blob, Organism, Solid };

/// "tree", "shell", ...
const char* speciesKindName(SpeciesKind kind);

/// An explicit camera (`render.camera:`); unset parts come from the automatic framing.
struct CameraSpec {
  std::optional<Vec3> position;    ///< `position: [x, y, z]`, the eye
  std::optional<Vec3> target;      ///< `target: [x, y, z]` (default: the center of the framed box)
  std::optional<double> distance;  ///< `distance`: eye at view.azimuth/elevation this far from target
};

/// How a species is shown: image size, camera, colors, light.
struct SpeciesRender {
  int width = 800;                     ///< `width`, pixels
  int height = 600;                    ///< `height`, pixels
  int samples = 4;                     ///< `samples`, camera samples per pixel
  render::ViewSpec view;               ///< `view: {azimuth, elevation, fov, margin}`
  render::SkeletonStyle style;         ///< `wood`, `leaf`, `fruit`, `palette`, `radius_scale`, `organs`
  render::Background background = render::Background::Gradient;  ///< `background`
  Vec3 backgroundColor{0.80f, 0.85f, 0.90f};  ///< `background_color` (background: color)
  bool ground = true;                  ///< `ground`
  Vec3 groundColor{0.45f, 0.42f, 0.37f};  ///< `ground_color`
  double sunAzimuthDeg = -50.0;        ///< `sun: {azimuth, elevation}`
  double sunElevationDeg = 50.0;
  float exposure = 0.0f;               ///< `exposure`, stops
  std::optional<CameraSpec> camera;    ///< `camera: {position, target, distance}`
  float fill = 0.0f;                   ///< `fill`: strength of an unshadowed light from the camera
  float sky = 0.5f;                    ///< `sky`: strength of the sky light
  render::Material surface{Vec3(0.72f, 0.60f, 0.48f), 0.45f, 0.05f};  ///< `color`, `roughness`, `specular`: blob surfaces

  /// Renderer settings for an image of width x height (threads 0 = all).
  render::RenderSettings settings(int imageWidth, int imageHeight) const;
};

/// One species, read and checked.
struct Species {
  SpeciesKind kind = SpeciesKind::Tree;
  std::string name;         ///< `name` (default: the file's stem)
  std::string description;  ///< `description`
  std::filesystem::path file;  ///< the species (or grammar) file as given
  bool bareGrammar = false;    ///< true when file is a `.lsys` grammar, not a species file

  // kind: tree
  std::string grammarText;      ///< the grammar's text
  std::string grammarFile;      ///< name used in the grammar's diagnostics
  int grammarLineOffset = 0;    ///< inline grammars: species-file line of grammar line 1, minus 1
  int grammarColOffset = 0;     ///< inline grammars: indentation of the block
  lsystem::GrammarOverrides overrides;  ///< `defines`, `steps`, `seed`
  size_t maxModules = 50'000'000;       ///< `max_modules`
  lsystem::TurtleSettings turtle;       ///< `turtle:` (angle filled from the grammar when unset)
  bool angleSet = false;                ///< `turtle.angle` given in the species file
  std::vector<int> stages;              ///< `stages`: derivation steps of the growth strip (empty = automatic)
  SpeciesRender render;                 ///< `render:`

  /// The parsed YAML (null for bare grammars); raw sections below point into it.
  std::shared_ptr<const YamlFile> yaml;
  std::optional<YNode> treeSection;   ///< `tree:` (BlobTree tree builder options)
  std::optional<YNode> shellSection;  ///< `shell:`
  std::optional<YNode> kindNode;      ///< the `kind:` value, for errors about the kind
  PathPolicy policy;  ///< the policy it was loaded with; readers of raw sections resolve files with it
};

/// Reads a species file or a bare grammar (chosen by extension: .yaml/.yml or .lsys).
/// Referenced files must satisfy policy. Throws InputError with every diagnostic.
Species loadSpecies(const std::filesystem::path& path, const PathPolicy& policy = {});

/// Reads species text as if it were the file displayPath (tests). Throws as loadSpecies.
Species parseSpecies(std::string text, const std::string& displayPath, const PathPolicy& policy = {});

/// Parses and compiles the grammar of a tree species, with extra overrides applied on top
/// of the species' own (command line `-D`, `--steps`, `--seed`). Throws InputError; errors
/// of an inline grammar point into the species file.
lsystem::Grammar speciesGrammar(const Species& species, const lsystem::GrammarOverrides& extra = {});

/// Turtle settings for species with grammar: the species' settings, with the angle from
/// the grammar's `angle:` when the species sets none (90 when neither does).
lsystem::TurtleSettings speciesTurtle(const Species& species, const lsystem::Grammar& grammar);

/// Growth stages for a derivation of `steps` steps: species.stages when given (each
/// clamped to steps), else up to `count` evenly spaced steps ending at `steps`.
std::vector<int> growthStages(const Species& species, int steps, int count = 5);

/// The species files of a folder (`*.yaml`, `*.yml`), sorted by name.
std::vector<std::filesystem::path> listSpeciesFiles(const std::filesystem::path& folder);

}  // namespace sprig
