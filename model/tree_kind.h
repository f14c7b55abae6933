#pragma once
/// `kind: tree` (and bare `.lsys` grammars): a grammar grown by the turtle into a skeleton,
/// shown as a skeleton preview or, with a `tree:` section, as a BlobTree tree
/// (organisms/tree_builder, Galbraith et al., "BlobTree Trees").

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "blobtree/compiled.h"
#include "core/mesh.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/turtle.h"
#include "lsystem/view_file.h"
#include "model/kinds.h"
#include "organisms/tree_builder.h"
#include "organisms/tree_options.h"

namespace sprig {

/// The keys of a tree species, read and checked.
class TreeSpec : public KindSpec {
 public:
  std::string grammarText;      ///< the grammar's text
  std::string grammarFile;      ///< name used in the grammar's diagnostics
  int grammarLineOffset = 0;    ///< inline grammars: species-file line of grammar line 1, minus 1
  int grammarColOffset = 0;     ///< inline grammars: indentation of the block
  lsystem::GrammarOverrides overrides;  ///< `defines`, `steps`, `seed`
  size_t maxModules = 50'000'000;       ///< `max_modules`
  lsystem::TurtleSettings turtle;       ///< `turtle:` (angle filled from the grammar when unset)
  bool angleSet = false;                ///< `turtle.angle` given in the species file
  std::optional<organisms::TreeOptions> surface;  ///< `tree:` (BlobTree tree builder options)
  /// A cpfg grammar (`.l`): its view file when it has one (speciesTurtle applies it, or
  /// cpfg's defaults without one).
  std::optional<lsystem::ViewFile> view;
  /// The grammar parsed at load with the species' own overrides (shares its compiled form:
  /// copies are free); speciesGrammar returns it when no command-line override is given.
  std::optional<lsystem::Grammar> grammar;

  std::string checkSummary(const Species& species) const override;
  std::unique_ptr<KindModel> makeModel(const Species& species, const ModelOptions& options) const override;
};

/// Reads the tree keys of a species file (grammar, defines, steps, seed, max_modules,
/// turtle, tree) and parses the grammar, adding every error to diags.
std::shared_ptr<const KindSpec> readTreeSpec(MapReader& top, Species& species, DiagnosticList& diags);

/// A bare grammar as a tree species with default settings. Throws InputError when the file
/// cannot be read or the grammar has errors. A cpfg grammar (`NAME.l`) is read with the view
/// file `NAME.v` beside it when there is one (lsystem/view_file.h); Species::notes then says
/// which of cpfg's defaults were used.
Species speciesFromGrammarFile(const std::filesystem::path& path);

/// A vlab object folder: the cpfg grammar and view file its `specifications` name on its
/// `cpfg` line, else its only `.l` file with an `axiom:` and the `.v` of the same name (or
/// its only `.v`). Throws InputError when the folder holds no such grammar or several, and
/// at the `specifications` line when a file it names leaves policy's root (the object's
/// files pass the same path policy as a species file's references).
Species speciesFromCpfgObject(const std::filesystem::path& folder, const PathPolicy& policy);

/// The tree keys of species. Throws InputError when the species is not a tree.
const TreeSpec& treeSpec(const Species& species);

/// Parses and compiles the grammar of a tree species, with extra overrides applied on top
/// of the species' own (command line `-D`, `--steps`, `--seed`). Throws InputError; errors
/// of an inline grammar point into the species file.
lsystem::Grammar speciesGrammar(const Species& species, const lsystem::GrammarOverrides& extra = {});

/// How the module strings of species print: cpfg's grammars (`.l`) hold 32-bit float
/// parameters and print in their shortest float form; others as doubles. Any kind.
lsystem::FormatOptions speciesStringFormat(const Species& species);

/// diags of the species' grammar, moved into the species file when the grammar is written
/// inline (`grammar: |`); unchanged otherwise.
std::vector<Diagnostic> inSpeciesFile(const Species& species, const TreeSpec& tree, std::vector<Diagnostic> diags);

/// Turtle settings for species with grammar: the species' settings, with the angle from
/// the grammar's `angle:` when the species sets none (90 when neither does).
lsystem::TurtleSettings speciesTurtle(const Species& species, const lsystem::Grammar& grammar);

/// One frame of a growth animation: the string after derivation step `stage`, with the
/// modules created in that step drawn grown by `fraction`.
struct GrowthFrame {
  int stage = 0;         ///< derivation step
  double fraction = 1;   ///< growth of the modules created in that step, 0..1
};

/// The frames for stages first..last with framesPerStage frames per step: {first, 1}, then
/// for each later stage k fractions 1/K .. K/K, so stage k's last frame is its full
/// skeleton. Returns 1 + (last - first) * framesPerStage frames.
std::vector<GrowthFrame> growthFrames(int first, int last, int framesPerStage);

/// Growth stages for a derivation of `steps` steps: species.stages when given (each
/// clamped to steps), else up to `count` evenly spaced steps ending at `steps`.
std::vector<int> growthStages(const Species& species, int steps, int count = 5);

/// Reads a `tree:` section (every key documented in docs/TREES.md) on top of defaults.
organisms::TreeOptions readTreeOptions(const YNode& section, DiagnosticList& diags,
                                       const organisms::TreeOptions& defaults = {});

/// Reads tree options from YAML text (tests). Throws InputError.
organisms::TreeOptions parseTreeOptions(std::string text, const std::string& displayPath);

/// A skeleton drawn directly (organisms/skeleton_geometry.h) with the species' preview
/// style: internodes as tapered curves, organs as flat leaves and spheres, cpfg's `@L` labels
/// as text (model/cpfg_labels.h).
render::Geometry skeletonPreview(const lsystem::Skeleton& skeleton, const SkeletonStyle& style);

/// A tree's BlobTree surface for one skeleton: the tree, its compiled form and its leaves.
struct TreeSurface {
  organisms::TreeOptions options;
  organisms::TreeBlob blob;
  std::shared_ptr<const blobtree::CompiledBlob> compiled;
  CurveSet axes;  ///< the internode cones' axes (drawn at a minimum pixel width where thin)
  Mesh leaves;
};

/// Builds the BlobTree surface of skeleton with options.
TreeSurface buildTreeSurface(const lsystem::Skeleton& skeleton, const organisms::TreeOptions& options);

}  // namespace sprig
