#pragma once
/// The L-system grammar language: parsing a cpfg-compatible `.lsys` file into a Grammar.
///
/// A Grammar is immutable once parsed: the symbol table, the axiom, the compiled
/// productions (successor templates and expression bytecode, see lsystem/detail/program.h)
/// and the header values (name, derivation length, seed, angle). Copies are cheap: they
/// share the compiled program. The language is documented in docs/GRAMMAR.md.
///
/// Symbols: the table starts with the built-in turtle symbols (kTurtleSymbols, in that
/// order), then the grammar's own symbols in order of first appearance. Multi-character
/// names are declared with `module Apex, Leaf`; strings are tokenized by longest match
/// against the declared and built-in multi-character names, otherwise one character is
/// one symbol. `~` followed by a letter is one symbol (`~l`, a named predefined surface).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"
#include "lsystem/cpfg_curve.h"
#include "lsystem/cpfg_function.h"
#include "lsystem/module_string.h"

namespace sprig::lsystem {

namespace detail {
struct Program;
}

/// Built-in turtle symbols, interned first in this order in every grammar's SymbolTable
/// (so their ids are 0, 1, 2, ...). The turtle is documented in docs/TURTLE.md.
inline constexpr const char* kTurtleSymbols[] = {
    "F", "f", "G", "g", "+", "-", "&", "^", "\\", "/", "|", "$", "[", "]",
    "!", "'", "{", ".", "}", "~", "%", "@Ts", "@v", "@O", "@Tf", "@o", "@c",
    "#", ";", ",", "@Ti", "@Td", "@Tp", "@M", "@R", "@D", "@Di", "@Dd", "@!",
};

/// One `#define` constant replaced from outside the grammar (`-D NAME=VALUE`, a species file).
struct DefineOverride {
  std::string name;
  double value = 0;
  SourceLoc loc;  ///< where the override was written (command line, species file), for errors
};

/// Values that replace what a grammar file says.
struct GrammarOverrides {
  /// Replace `#define NAME` values; an unknown NAME is an InputError (with "did you mean").
  std::vector<DefineOverride> defines;
  std::optional<int> derivationLength;  ///< replaces `derivation length:`
  /// Where derivationLength was written (a species' `steps:`); when known and the grammar
  /// writes another length, parsing adds a note there naming both values.
  SourceLoc derivationLengthLoc;
  std::optional<uint64_t> seed;         ///< replaces `seed:`
  /// cpfg's function files of the grammar's view file (ViewFile::functions), which
  /// `func(n, x)` reads; without them `func` is an error.
  std::vector<CpfgFunction> cpfgFunctions;
  /// cpfg's curve files of the grammar's view file (ViewFile::curves), which `curveX(n, t)`,
  /// `curveY`, `curveZ` and `curveGAL(n)` read; without them these are errors.
  std::vector<CpfgCurve> cpfgCurves;
  /// The ids of the view file's surfaces (ViewFile::surfaces), which `~X` may name; any
  /// other `~X` in a `.l` grammar draws nothing, as in cpfg (a warning).
  std::string cpfgSurfaceIds;
  /// The ids of the view file's `tsurface:` lines, which cpfg draws and Sprig does not read:
  /// a `~X` of one is an error (any other id no `surface:` line defines draws nothing).
  std::string cpfgUndrawnSurfaceIds;
  /// cpfg: the names of a view file's `function set:` functions (ViewFile::functionNames),
  /// which the preprocessor defines as 1, 2, ... in a `.l` grammar.
  std::vector<std::string> cpfgFunctionNames;
  /// cpfg's environment file (`-e FILE.e`, relative to the working folder; empty: none): the derivation
  /// runs the environmental program it names in the grammar's folder and exchanges the `?E`
  /// modules with it (DeriveOptions::environment). Not read by the parser.
  std::string cpfgEnvironment;
  /// Longest wait for that program, in seconds (EnvironmentOptions::timeoutSeconds).
  double cpfgEnvironmentTimeout = 60.0;
};

/// A parsed, compiled L-system.
class Grammar {
 public:
  Grammar();

  /// `lsystem:` name, or the file's stem when absent.
  const std::string& name() const;
  /// The file name the grammar was parsed from (used in every diagnostic).
  const std::string& fileName() const;
  /// `derivation length:` after overrides (0 when absent).
  int derivationLength() const;
  /// `seed:` after overrides (0 when absent).
  uint64_t seed() const;
  /// `angle:` in degrees, the turtle's default turn angle; nullopt when the file has none.
  std::optional<double> angleDeg() const;
  /// Every symbol the grammar names (built-ins first).
  const SymbolTable& symbols() const;
  /// The axiom with its parameters evaluated.
  const ModuleString& axiom() const;
  /// Value of a `#define` constant after overrides, nullopt if undefined.
  std::optional<double> define(std::string_view name) const;
  /// Names of every `#define`, in file order.
  std::vector<std::string> defineNames() const;
  /// Number of productions in the main block (not decomposition or interpretation rules).
  size_t productionCount() const;
  /// True when the grammar has `interpretation:` (homomorphism) rules.
  bool hasInterpretation() const;
  /// True when the grammar is in cpfg's own notation (a `.l` file: docs/GRAMMAR.md, "cpfg
  /// compatibility"); false for Sprig's `.lsys` notation. The turtle must then be run with
  /// TurtleSettings::cpfg set.
  bool cpfgNotation() const;
  /// True when the axiom or a successor turns without an angle (`+`, `-`, `&`, `^`, `\`,
  /// `/` without a parameter), so that the default turn angle is used.
  bool usesDefaultAngle() const;

  /// The warnings and notes of parsing, in file order (a multi-letter word written without
  /// its `module` declaration, an overridden `derivation length:`).
  const std::vector<Diagnostic>& warnings() const;

  /// The format strings of cpfg's `@L("format", ...)` (and printf), numbered by `@L`'s first
  /// parameter: for TurtleSettings::labelFormats.
  std::shared_ptr<const std::vector<std::string>> strings() const;

  /// The compiled program (internal; used by Deriver).
  const detail::Program& program() const { return *program_; }

 private:
  friend Grammar parseGrammar(std::string_view, const std::string&, const GrammarOverrides&);
  std::shared_ptr<const detail::Program> program_;
};

/// Parses and compiles a grammar. Every error in the text is collected and thrown together
/// as one InputError with `fileName:line:col` positions (1-based).
/// Throws InputError also for an override naming an unknown `#define`.
Grammar parseGrammar(std::string_view text, const std::string& fileName, const GrammarOverrides& overrides = {});

/// Reads path and parses it; a missing or unreadable file is an InputError at `path`.
Grammar loadGrammar(const std::string& path, const GrammarOverrides& overrides = {});

/// Tokenizes a module string written in grammar notation (`F(1)[+A(2,3)]`), parameters
/// being constant expressions, interning new single-character symbols into symbols.
/// Throws InputError (positions relative to text, reported in fileName).
ModuleString parseModuleString(std::string_view text, SymbolTable& symbols, const std::string& fileName = "<string>");

}  // namespace sprig::lsystem
