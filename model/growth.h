#pragma once
/// The one growth engine of tree species: grammar -> derivation -> interpretation rules ->
/// turtle -> Skeleton, at any step, as `sprig derive`, `preview`, `render`, `mesh`,
/// `animate` and the gallery need it (docs/GRAMMAR.md "Growth over time").
///
/// A species is derived once per engine: asking for a later step continues the derivation.
/// The pass over every step (below) keeps each step's interpreted string while they fit in
/// kSnapshotBytes (256 MiB), so strips and animations revisit earlier steps without deriving
/// again; beyond that an earlier step restarts the derivation (a derivation is
/// deterministic, so a branch of step 5 is the same branch at step 6). Two skeletons are
/// offered:
/// - skeletonAt(step): the string after `step` steps drawn as it is (what `derive` reports);
/// - skeletonAt(step, fraction): a growth frame, the modules created in `step` drawn grown by
///   `fraction` (TurtleSettings::growthStep), scaled from growthStart(step) at fraction 0.
/// The growth frames' camera box and growthStart need every step drawn once; that pass runs
/// the first time either is asked for.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"
#include "lsystem/skeleton.h"
#include "lsystem/turtle.h"

namespace sprig {

struct Species;

/// What to grow beyond the species' own settings.
struct GrowthOptions {
  lsystem::GrammarOverrides extra;  ///< command-line -D, --steps, --seed
  int lastStep = -1;                ///< stop after this step (-1 = the species' steps; clamped to them)
  std::string progressLabel;        ///< progress bar over derivation steps; empty = none
};

/// The box a camera frames for skeleton (a unit box around the origin when it is empty).
DBox3 framingBox(const lsystem::Skeleton& skeleton);

/// A tree species growing. Not thread-safe; not copyable.
class GrowthEngine {
 public:
  /// Parses the species' grammar with options.extra on top of its own overrides. Throws
  /// InputError for grammar errors or a species that is not a tree.
  explicit GrowthEngine(const Species& species, const GrowthOptions& options = {});
  ~GrowthEngine();
  GrowthEngine(const GrowthEngine&) = delete;
  GrowthEngine& operator=(const GrowthEngine&) = delete;

  /// The last step grown (the species' steps, or options.lastStep when smaller).
  int lastStep() const { return lastStep_; }
  /// The derivation's seed.
  uint64_t seed() const;
  /// Ids and names of the grammar's modules.
  const lsystem::SymbolTable& symbols() const;

  /// Memory the per-step snapshots may take (bytes).
  static constexpr size_t kSnapshotBytes = size_t(256) << 20;

  /// Modules in the string after `step` steps.
  size_t moduleCount(int step);
  /// The module string after `step` steps (before interpretation rules). Derives as needed;
  /// throws InputError for derivation errors (module limit, non-finite values), Cancelled
  /// on a signal, std::invalid_argument for a step outside 0..lastStep().
  const lsystem::ModuleString& modulesAt(int step);
  /// The string after `step` steps drawn as it is; end, when given, receives the turtle's
  /// state after the last module.
  lsystem::Skeleton skeletonAt(int step, lsystem::TurtleState* end = nullptr);
  /// skeletonAt(step)'s internode count, total length and bounds, and its organs, without
  /// storing its internodes (Turtle::summarize).
  lsystem::SkeletonSummary summaryAt(int step, lsystem::TurtleState* end = nullptr);
  /// The growth frame (step, fraction): modules created in step drawn grown by fraction.
  lsystem::Skeleton skeletonAt(int step, double fraction);

  /// Union of the full skeletons' framing boxes over steps 0..lastStep (the growth camera).
  const DBox3& frameBox();
  /// Scale of step k's new modules at fraction 0: chosen so that the total internode length
  /// is continuous from step k-1 (full) to step k (fraction 0), clamped to [0, 1]. 0 for
  /// grammars that keep old modules (node rewriting: new organs grow from nothing); 1/2 for
  /// F -> FF, whose modules are all new in every step.
  double growthStart(int step);

 private:
  void measure();
  void advanceTo(int step);
  /// The interpreted string of step: a snapshot when kept, else the deriver's.
  const lsystem::ModuleString& interpretedAt(int step);
  lsystem::Skeleton draw(const lsystem::ModuleString& interpreted, const lsystem::TurtleSettings& settings,
                         lsystem::TurtleState* end);

  std::unique_ptr<lsystem::Grammar> grammar_;
  std::unique_ptr<lsystem::Deriver> deriver_;
  lsystem::TurtleSettings turtle_;
  std::string progressLabel_;
  int lastStep_ = 0;
  bool measured_ = false;
  DBox3 frameBox_;
  std::vector<double> start_;          ///< growthStart per step
  std::vector<lsystem::ModuleString> snapshots_;  ///< interpreted string per step (measure pass; empty when too large)
  std::vector<size_t> moduleCounts_;   ///< modules after each step (measure pass)
  /// The interpreted string of step interpretedStep_, when the grammar has interpretation
  /// rules; without them the turtle reads the deriver's string itself (no copy: a copy of
  /// 1.8 million modules costs `sprig derive` a fifth of its time in page faults).
  lsystem::ModuleString interpreted_;
  /// interpreted_, or the deriver's current string.
  const lsystem::ModuleString& interpreted() const;
  int interpretedStep_ = -1;
  /// A view file command that changes the drawing and that Sprig does not implement
  /// (ViewFile::unsupportedDrawing): thrown by every drawing, not by a derivation.
  std::optional<Diagnostic> unsupportedDrawing_;
  void refuseDrawing() const;
};

}  // namespace sprig
