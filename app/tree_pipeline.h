#pragma once
/// Growing a tree species: grammar -> derivation -> interpretation rules -> turtle -> Skeleton,
/// with skeletons of intermediate growth stages on the way (one derivation for all).

#include <chrono>
#include <optional>
#include <vector>

#include "app/species.h"
#include "lsystem/derive.h"
#include "lsystem/skeleton.h"
#include "lsystem/turtle.h"

namespace sprig {

/// What to grow beyond the species' own settings.
struct GrowOptions {
  lsystem::GrammarOverrides extra;  ///< command-line -D, --steps, --seed
  std::vector<int> stageSteps;      ///< also keep skeletons after these steps (<= final steps)
  bool progress = true;             ///< progress bar over derivation steps
};

/// A skeleton after some derivation step.
struct GrownStage {
  int step = 0;
  size_t modules = 0;
  lsystem::Skeleton skeleton;
};

/// The result of growing a tree species.
struct GrownTree {
  lsystem::Grammar grammar;
  lsystem::ModuleString modules;  ///< the final string (after derivation, before interpretation rules)
  lsystem::SymbolTable symbols;   ///< ids of modules
  lsystem::Skeleton skeleton;     ///< the final skeleton
  lsystem::TurtleState end;       ///< turtle state after the last module
  int steps = 0;
  uint64_t seed = 0;
  std::vector<GrownStage> stages;  ///< one per GrowOptions::stageSteps entry, same order
  double deriveSeconds = 0;
  double turtleSeconds = 0;
};

/// Grows species (kind tree or a bare grammar). Throws InputError for grammar errors and
/// derivation errors (module limit, non-finite values), Cancelled on a signal.
GrownTree growTree(const Species& species, const GrowOptions& options = {});

}  // namespace sprig
