#pragma once
/// Helpers shared by the `sprig` subcommands.

#include <cstdint>
#include <ostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "app/commands.h"
#include "lsystem/grammar.h"
#include "model/model.h"
#include "render/camera.h"

namespace sprig {

/// Overrides from `-D NAME=VALUE` flags, `--steps` (ignored when < 0) and `--seed`
/// (ignored when < 0). Throws UsageError for a malformed -D.
lsystem::GrammarOverrides commandLineOverrides(const std::vector<std::string>& defines, int steps, int64_t seed);

/// `--steps`, `--seed` and `-D NAME=VALUE`: a tree's derivation overrides on the command line.
struct GrowthFlags {
  int steps = -1;      ///< -1 = the species' steps
  int64_t seed = -1;   ///< -1 = the species' seed
  std::vector<std::string> defines;  ///< NAME=VALUE
  std::string environment;           ///< cpfg's `-e FILE.e` (empty: none)
  double environmentTimeout = 60.0;  ///< --enviro-timeout, seconds
  /// The overrides. Throws UsageError for a malformed -D.
  lsystem::GrammarOverrides overrides() const;
};

/// Registers --steps, --seed and -D on sub.
void addGrowthFlags(CLI::App& sub, GrowthFlags& flags);

/// `--stage K`, `--fraction F` (trees) and `--age DEG` (shells): which stage to build.
struct StageFlags {
  int stage = -1;         ///< -1 = the final stage
  double fraction = 1.0;  ///< growth of the stage's newest modules
  double age = -1.0;      ///< -1 = the species' age
  /// The stage of model these flags name. Throws UsageError for a stage or age the kind lacks.
  Stage resolve(const SpeciesModel& model) const;
};

/// Registers --stage, --fraction and --age on sub.
void addStageFlags(CLI::App& sub, StageFlags& flags);

/// Prints one printf-formatted line (a command's summary) to os unless g.quiet.
[[gnu::format(printf, 3, 4)]] void note(const GlobalOptions& g, std::ostream& os, const char* format, ...);

/// Prints the notes and warnings of reading species (cpfg defaults used, view file keys
/// ignored) to stderr, unless g.quiet. Under `--strict` (g.strict) the warnings are
/// thrown as errors instead (InputError).
void printNotes(const GlobalOptions& g, const Species& species);

/// Parses `--wind SPEED[,DIRECTION]`: m/s in [0, 60] and degrees in [-360, 360] (default
/// 0). Throws UsageError.
void parseWind(const std::string& text, double& speed, double& direction);

/// Parses `--view AZ,EL` or `AZ,EL,FOV` (degrees) into view. Throws UsageError.
void parseView(const std::string& text, render::ViewSpec& view);

}  // namespace sprig
