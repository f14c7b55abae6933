#pragma once
/// Derivation: rewriting a ModuleString with a Grammar's productions, step by step.
///
/// Each step reads the current string and writes the next one into a second buffer
/// (structure of arrays, no heap object per module); the buffers then swap. Productions
/// are found through a table indexed by symbol id; successors are templates whose
/// parameter expressions run on a small bytecode VM (lsystem/detail/program.h).
/// Stochastic choices and `ran`/`nran` draw from an Rng seeded per module with
/// deriveSeed(seed, {step, moduleIndex}), so results never depend on thread count. Files
/// in cpfg's notation draw cpfg's own sequences instead (detail::CpfgRandom: drand48 for
/// the choice, one erand48 stream for the random functions), in string order, as a step
/// visits the modules one after another on one thread.
/// After each step the `decomposition:` rules are applied (depth-limited) and `%` cuts
/// remove the rest of their branch (in cpfg's notation when the next step reaches them,
/// as cpfg does).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "lsystem/cpfg_environment.h"
#include "lsystem/grammar.h"
#include "lsystem/module_string.h"
#include "lsystem/turtle.h"

namespace sprig::lsystem {

/// Settings for one derivation. Unset optionals take the grammar's values.
struct DeriveOptions {
  std::optional<int> steps;       ///< number of steps; default Grammar::derivationLength()
  std::optional<uint64_t> seed;   ///< default Grammar::seed()
  /// Limit on modules in any string; exceeding it throws InputError
  /// "derivation would exceed N modules at step k" before the memory is allocated
  /// (located at the grammar's `derivation length:` or, with steps set, its `axiom:`).
  size_t maxModules = 50'000'000;
  /// Record in ModuleString::birthSteps the step that created each module (0 = axiom).
  /// Off by default: it then costs nothing.
  bool trackBirthSteps = false;
  /// The turtle that fills cpfg's query modules (`?P ?H ?L ?U`, docs/GRAMMAR.md): when the
  /// grammar has any, the axiom and the string after every step are interpreted (with the
  /// `interpretation:` rules) by a turtle with these settings and each query module reached
  /// gets the turtle's position, heading, left or up vector (cpfg's up: -U of Sprig's
  /// frame) in its first 2 or 3 parameters. Unset: the grammar's own (cpfg's defaults for a
  /// `.l`, its `angle:` or 45 degrees).
  std::optional<TurtleSettings> queryTurtle;
  /// Fill the query modules after the last step too (cpfg interprets the final string when
  /// it draws it). False: the string of step steps() (and of any step past it) keeps its
  /// query modules as that step wrote them, as `cpfg -g -str` writes it when the view file
  /// has a `box:` line (control.c, CalculateViewVolume interprets only without one); a
  /// later step() fills them first, as cpfg does when the next step starts.
  bool queriesAfterLastStep = true;
  /// cpfg's environmental program (`-e FILE.e`, docs/GRAMMAR.md "Environmental programs"):
  /// before every step the string is interpreted as for the query modules, each `?E` module
  /// the turtle reaches is sent to it, and its answers set those modules' parameters (as
  /// cpfg's default `environment display: after`: the final string is not sent). Null:
  /// `?E` modules keep their values, as cpfg's do without -e. restart() restarts it.
  std::shared_ptr<EnvironmentProgram> environment;
  /// cpfg's `environment display: before` (a view file's, ViewFile::environmentBefore): the
  /// exchange follows every step instead of preceding it, and the axiom's comes first, so
  /// the final string holds the program's answers.
  bool environmentAfterEachStep = false;
  /// Called after every completed step with (step, module count); may be empty.
  std::function<void(int step, size_t modules)> onStep;
};

/// Derives a grammar step by step. Not thread-safe; cheap to construct.
///
/// Errors (InputError): a module limit overrun (`file:line:col: error: derivation would
/// exceed N modules at step k`, at the grammar's `derivation length:` header when that sets
/// the number of steps, else at its `axiom:`), a non-finite parameter (`file:line:col: error: non-finite parameter
/// value (inf) in production 'A(x)' at step k (parameter 1 of 'B')`, at the production),
/// a NaN condition. After an error the Deriver keeps the string of the last completed step.
class Deriver {
 public:
  /// Starts from the grammar's axiom: decomposed and cut in Sprig's notation; in cpfg's as
  /// written (cpfg decomposes and cuts it in the first step). The Deriver shares the grammar's
  /// compiled program, so the Grammar object itself may go away.
  explicit Deriver(const Grammar& grammar, DeriveOptions options = {});
  ~Deriver();
  Deriver(Deriver&&) noexcept;
  Deriver& operator=(Deriver&&) noexcept;

  /// Starts again from the axiom, keeping the buffers' memory (derive again, cheaply).
  void restart();
  /// Performs one derivation step (even past steps()); returns the new string.
  const ModuleString& step();
  /// Performs the remaining steps up to steps() and returns the final string.
  const ModuleString& derive();
  /// The current string (the axiom before any step).
  const ModuleString& current() const;
  /// Steps performed so far.
  int stepsDone() const;
  /// Target number of steps (options or grammar); after cpfg's `stop(x)` ran in a step
  /// (a production's or a Start/StartEach/EndEach block's statements), that step.
  int steps() const;
  /// The seed in use (in a .lsys file, after `srand(s)` in a Start/StartEach/EndEach/End block, s;
  /// a .l file's srand reseeds cpfg's own stream instead).
  uint64_t seed() const;
  /// The grammar's symbol table (ids in every string this Deriver produces).
  const SymbolTable& symbols() const;
  /// True when the grammar has `interpretation:` rules (else interpret(s) is a copy of s).
  bool hasInterpretation() const;
  /// Applies the `interpretation:` (homomorphism) rules to s, recursively up to the
  /// block's `maximum depth` (default 1), as the turtle reads it; the result keeps
  /// birth steps when s has them. Returns a copy of s when there are no such rules.
  /// Random draws use deriveSeed(seed, {kInterpretStream, moduleIndex}).
  ModuleString interpret(const ModuleString& s) const;
  /// Modules written in total over every step so far (the benchmark's throughput count).
  uint64_t modulesWritten() const;

  /// Stream id mixed into interpretation seeds (distinct from any step number).
  static constexpr uint64_t kInterpretStream = 0xfffffffffffffff0ull;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One-call form: derives grammar with options and returns the final string.
ModuleString derive(const Grammar& grammar, const DeriveOptions& options = {});

/// Options for formatModuleString.
struct FormatOptions {
  /// Characters per line before wrapping at a module boundary; 0 = one line.
  size_t wrapColumn = 0;
  /// Print each parameter in the shortest form that reads back as the same 32-bit float
  /// (a grammar in cpfg's notation, whose parameters are floats: 1.99999 rather than
  /// 1.9999899864196777).
  bool floatParams = false;
};

/// s in the grammar's own notation: `F(1.5)[+A(2,3)]`. Numbers print in their shortest
/// round-trip form (as doubles, or floats with FormatOptions::floatParams); a space separates a multi-character name from a following module
/// whose name would otherwise merge with it.
std::string formatModuleString(const ModuleString& s, const SymbolTable& symbols, const FormatOptions& options = {});

/// Number of modules with symbol name in s (0 if the symbol is unknown).
size_t countSymbol(const ModuleString& s, const SymbolTable& symbols, std::string_view name);

}  // namespace sprig::lsystem
