#pragma once
/// The grammar's arithmetic expressions (`x*0.9`, `t > 2 && ran(1) < 0.5`, `sin(a)`):
/// parsing a Span of a cleaned line and compiling it to the bytecode of
/// lsystem/detail/program.h. Private to lsystem/; the grammar parser calls it.

#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/rng.h"
#include "lsystem/detail/program.h"
#include "lsystem/detail/scanner.h"

namespace sprig::lsystem::detail {

/*
 * ExpressionParser: recursive descent over the tokens of one span (numbers, names,
 * operators; precedence from `||` up to unary operators and right-associative `^`) into
 * a small node tree, which is then emitted in postfix order onto a shared code vector
 * with constant folding: a subtree of constants (`#define`s included) becomes one Const,
 * except random draws. Names resolve to the production's formal parameters first, then
 * to `#define`s. Errors are reported through the scanner, at the token's column; a failed
 * expression leaves the code vector as it was.
 *
 * usesRandom() records whether anything compiled since clearRandom() calls `ran` or
 * `nran` (a production that draws needs a random stream).
 */
class ExpressionParser {
 public:
  /// Reads text and reports errors through scanner, resolves names in defines, and
  /// appends bytecode to code. All three must outlive the parser.
  ExpressionParser(Scanner& scanner, const std::unordered_map<std::string, double>& defines, std::vector<Instr>& code)
      : scanner_(scanner), defines_(defines), code_(code) {}

  /// Compiles the expression in sp, with formal parameters vars (register i is vars[i]),
  /// onto the code vector. `what` names the expression in errors ("condition"). Returns
  /// false (error reported, code unchanged) on failure, also for an expression nested
  /// deeper than the VM's stack or one that folds to a non-finite constant.
  bool compile(Span sp, const std::vector<std::string>& vars, const char* what);
  /// A constant expression (defines allowed, no parameters, no random draws): its value,
  /// or nullopt with an error reported. The code vector is left unchanged.
  std::optional<double> constant(Span sp, const std::string& what);
  /// A successor parameter: as an Arg of the cheapest kind that computes it (a constant,
  /// a register, `x op c`), or else an Expr range of newly appended code. A failed
  /// compilation returns a Const 0 Arg (the error is reported).
  Arg compileArg(Span sp, const std::vector<std::string>& vars);
  /// A parameter of a module written with constant expressions (an axiom, a string given
  /// to parseModuleString): its value, drawing from rng for `ran`/`nran`. nullopt with an
  /// error reported when it fails to compile, draws without an rng, or is not finite.
  /// The code vector is left unchanged; usesRandom() is not affected.
  /// deferred (cpfg's axiom): a parameter that reads cpfg's global variables keeps its code
  /// in the code vector, *deferred is set to it and 0 is returned (the Deriver evaluates it
  /// after the `Start:` block, as cpfg's Rewind does); without it that is an error.
  std::optional<double> evaluate(Span sp, Rng* rng, CodeRange* deferred = nullptr);
  /// The left side `name[i][j]` of an assignment to an element of cpfg's array (in sp):
  /// compiles its row-major flat index onto the code vector and returns the array's
  /// number, or nullopt with an error reported (code unchanged).
  std::optional<int> compileElement(Span sp, const std::vector<std::string>& vars);
  /// The number of cpfg's array name (Program::cpfg.arrays), or -1.
  int arrayId(std::string_view name) const;

  /// cpfg's global variables (assigned in `Start:` ... blocks): a name not among an
  /// expression's variables that is global k reads register kMaxVars - 1 - k. Null: none.
  void setGlobals(const std::vector<std::string>* globals) { globals_ = globals; }

  /// Whether an expression compiled since clearRandom() draws random numbers.
  bool usesRandom() const { return usesRandom_; }
  void clearRandom() { usesRandom_ = false; }
  /// The view file's function files `func(n, x)` may name (none when null).
  void setTables(const CpfgTables* tables) { tables_ = tables; }
  /// Whether cpfg's `srand` and `stop` may be called (only as statements, see
  /// grammar_parser.cpp); stopError is the message for a `stop` that may not.
  void allowEffects(bool srand, bool stop, const char* stopError) {
    allowSrand_ = srand;
    allowStop_ = stop;
    allowStopReason_ = stopError;
  }

 private:
  struct Node;
  struct Token;
  struct State;

  void lex(State& st);
  bool isPunct(const State& st, std::string_view p) const;
  int node(State& st, Op op, int a = -1, int b = -1, int c = -1);
  [[noreturn]] void unexpected(State& st, const char* what);
  /// One more level of nesting while the guard lives (an error past kMaxNesting levels).
  struct Nesting {
    int& depth;
    ~Nesting() { --depth; }
  };
  [[nodiscard]] Nesting nest(State& st);
  int parseConditional(State& st);
  int parseBinary(State& st, int level);
  int parseUnary(State& st);
  int parsePrimary(State& st);
  int parseCall(State& st, const Token& id);
  int parseFunc(State& st, const Token& id);
  int parseCurve(State& st, const Token& id, const std::string& name);
  int parseName(State& st, const Token& id);
  int parseIndices(State& st, const Token& id, int a);
  bool emit(const State& st, int n, int& depth, int& maxDepth);
  /// Emits the tree at root; past kMaxStack values deep, reports `what` is nested too deeply
  /// at the span's start, takes back the code after `before` and returns false.
  bool emitWithinStack(const State& st, int root, size_t before, const std::string& what);

  Scanner& scanner_;
  const std::unordered_map<std::string, double>& defines_;
  std::vector<Instr>& code_;
  bool usesRandom_ = false;
  const CpfgTables* tables_ = nullptr;
  bool allowSrand_ = false;
  bool allowStop_ = false;
  const char* allowStopReason_ = "cpfg's function 'stop' is supported only as a statement ('stop(1);')";
  const std::vector<std::string>* globals_ = nullptr;
};

}  // namespace sprig::lsystem::detail
