#pragma once
/// The compiled form of a Grammar: productions with successor templates and expression
/// bytecode. Private to lsystem/; parseGrammar writes it, Deriver reads it.
///
/// Expressions compile to a flat postfix tape (Instr) evaluated on a small value stack;
/// constants (`#define`s included) are folded at compile time, and the common argument
/// shapes `x`, `c`, `x op c` bypass the VM entirely (ArgKind). Formal parameters of a
/// production (left context, predecessor, right context, in textual order) live in one
/// register file `vars` of at most kMaxVars doubles.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"
#include "core/rng.h"
#include "core/types.h"
#include "lsystem/cpfg_curve.h"
#include "lsystem/cpfg_function.h"
#include "lsystem/detail/cpfg.h"
#include "lsystem/module_string.h"

namespace sprig::lsystem::detail {

inline constexpr int kMaxVars = 64;   ///< formal parameters per production
inline constexpr int kMaxStack = 64;  ///< expression nesting depth

enum class Op : uint8_t {
  Const, Var, Add, Sub, Mul, Div, Pow, Neg, Not, Lt, Le, Gt, Ge, Eq, Ne, And, Or,
  Sin, Cos, Tan, Asin, Acos, Atan, Atan2, Sqrt, Exp, Log, PowFn, Abs, Min, Max, Floor, Ceil, Sign,
  Ran, Nran,
  Select,  ///< `c ? a : b` (three operands, both evaluated)
  Round,   ///< cpfg's `trunc(x)`: floor(x + 0.5) (cpfg rounds, whatever the name says)
  Rem,     ///< cpfg's `a % b`: the remainder of the operands truncated to integers
  Bran,    ///< `bran(a, b)`: a beta(a, b) draw
  Biran,   ///< `biran(n, p)`: a binomial(n, p) draw
  // Statements (cpfg's `{ x = ...; if (...) {...} }` blocks); never inside an expression.
  Store,   ///< pops a value into register var
  Jz,      ///< pops a value; when it is 0, jumps to instruction c of the block
  Jmp,     ///< jumps to instruction c of the block
  Printf,  ///< cpfg's `printf(format, ...)`: pops c values, prints them to stderr with Program::strings[var]
  Srand,   ///< cpfg's `srand(s)`: reseeds cpfg's stream (Draws::cpfg), or records s as the seed of
           ///< later draws (Effects::reseed); value 0
  Stop,    ///< cpfg's `stop(x)`: asks the derivation to end after the current step (Effects::stop); value 0
  // cpfg's files (Effects::files; statements of the Start/StartEach/EndEach/End blocks only).
  Fopen,   ///< `fopen("name", "mode")`: pushes the file's index (-1 when it cannot be opened); Program::strings[var], [var + 1]
  Fprintf, ///< `fprintf(f, format, ...)`: pops c values and the index f, writes them with Program::strings[var]
  Fflush,  ///< `fflush(f)`: pops the index f
  Fclose,  ///< `fclose(f)`: pops the index f
  Func,    ///< cpfg's `func(n, x)`: function var (n - 1) of the view file's function files at x
  Curve,   ///< cpfg's `curveX/Y/Z(n, t)`: coordinate c (0, 1, 2) of curve var (n - 1) at arc length t
  CurveLength,  ///< cpfg's `curveGAL(n)`: the length of curve var (n - 1); pops nothing
  ArrayAt,     ///< cpfg's `a[i]`: checks index i of dimension c of array var, pushes it truncated
  ArrayLoad,   ///< pops a flat index, pushes element of array var
  ArrayStore,  ///< pops a value, then a flat index; stores the value into element of array var
};

/// One of cpfg's `define: { array name[d1][d2]... = {...}; }` arrays: its elements are
/// arrayInit[offset .. offset + size) at the start of every derivation, row-major.
struct CpfgArray {
  std::string name;
  std::vector<int> dims;
  uint32_t offset = 0;
  uint32_t size() const {
    uint32_t n = 1;
    for (int d : dims) n *= static_cast<uint32_t>(d);
    return n;
  }
};

/// The view file's function and curve files, which `func` and `curveX...` read.
struct CpfgTables {
  std::vector<CpfgFunction> functions;  ///< `function:` lines (`func(n, x)`), n = 1, 2, ...
  std::vector<CpfgCurve> curves;        ///< `curve:` lines (`curveX(n, t)`), n = 1, 2, ...
  std::vector<CpfgArray> arrays;        ///< `define: { array ... }` declarations
  std::vector<double> arrayInit;        ///< every array's initial elements, one after another
};

/// Throws the run-time error of an index i out of range in dimension d of array a.
[[noreturn]] void arrayIndexError(const CpfgArray& a, int d, double i);

/// What cpfg's `srand` and `stop` ask of the Deriver, recorded by evalCode.
/// The files cpfg's `fopen` opens (userfiles.cpp): at most kMaxFiles at once, their indices
/// taken from a stack of the free ones (the first file is 24, the next 23; a closed file's
/// index is the next one given); names are plain file names in folder (the grammar's).
class CpfgFiles {
 public:
  static constexpr int kMaxFiles = 25;
  explicit CpfgFiles(std::string folder = {}) : folder_(std::move(folder)) {
    for (int k = 0; k < kMaxFiles; ++k) free_.push_back(k);
  }
  CpfgFiles(const CpfgFiles&) = delete;
  CpfgFiles& operator=(const CpfgFiles&) = delete;
  ~CpfgFiles() { closeAll(); }
  void setFolder(std::string folder) { folder_ = std::move(folder); }
  /// The index of the file opened, or -1 (cpfg's "Cannot fopen", which Sprig makes an error).
  int open(const std::string& name, const std::string& mode);
  /// Writes format with the n values args to file f (when open: cpfg only warns otherwise).
  void print(double f, const std::string& format, const double* args, int n);
  void flush(double f);
  void close(double f);
  void closeAll();

 private:
  std::FILE* at(double f) const;
  std::string folder_;
  std::FILE* files_[kMaxFiles] = {};
  std::vector<int> free_;  ///< free indices, the next one given last
};

struct Effects {
  bool stop = false;    ///< `stop(x)` ran: end the derivation after the current step
  bool reseed = false;  ///< `srand(s)` ran: seed the later draws with seed
  double seed = 0;
  CpfgFiles* files = nullptr;  ///< cpfg's fopen and the like (Start/StartEach/EndEach/End blocks)
};

/// Most backward jumps one statement block may take (a `while` that never ends): past it
/// evalCode stops and returns NaN, which the deriver reports.
inline constexpr long kMaxLoopJumps = 10'000'000;

/// cpfg's random streams (generate.c SelectProd, utility.c): a stochastic production is
/// chosen with drand48, which `seed: s` (s not 0) seeds with seed48({s, 0, 155}); ran, nran,
/// bran and biran draw from a separate erand48 stream that starts at {0x330E, 0, 0} and
/// that only srand(a) reseeds, to {0x330E, a & 0xFFFF, a >> 16}.
struct CpfgRandom {
  Rand48 choice;
  Rand48 main = Rand48::fromWords(0x330E, 0, 0);
  int iset = 10;    ///< nran's state: 0 draws a new pair; cpfg starts it at 10 (first nran returns the mean)
  double gset = 0;  ///< nran's second deviate of the pair

  /// The streams of a derivation whose drand48 seed48 seeds with {seed, 0, 155} (0: not
  /// seeded, drand48 starts at 0). cpfg -g never seeds it, whatever `seed:` says; its
  /// interactive window seeds it with `seed:` (control.c, FirstRun).
  static CpfgRandom forSeed(uint64_t seed) {
    CpfgRandom r;
    if (seed != 0) r.choice = Rand48::fromWords(static_cast<uint16_t>(seed), 0, 155);
    return r;
  }
  void srand(double s) {
    const long a = static_cast<long>(std::clamp(s, -9.2e18, 9.2e18));
    main = Rand48::fromWords(0x330E, static_cast<uint16_t>(a & 0xFFFF), static_cast<uint16_t>((a >> 16) & 0xFFFF));
    iset = 0;
  }
  /// cpfg's nran(mean, sd): the polar method, two deviates per pair of accepted draws.
  double nran(double mean, double sd) {
    if (iset != 0) {
      iset = 0;
      return gset * sd + mean;
    }
    double v1, v2, rsq;
    do {
      v1 = 2.0 * main.next() - 1.0;
      v2 = 2.0 * main.next() - 1.0;
      rsq = v1 * v1 + v2 * v2;
    } while (rsq >= 1.0 || rsq == 0.0);
    const double fac = std::sqrt(-2.0 * std::log(rsq) / rsq);
    gset = v1 * fac;
    iset = 1;
    return v2 * fac * sd + mean;
  }
};

/// Where an evaluation's random draws come from: Sprig's per-module PCG stream, or (a cpfg
/// file) cpfg's sequential streams.
struct Draws {
  Rng* pcg = nullptr;
  CpfgRandom* cpfg = nullptr;
  double uniform() { return cpfg ? cpfg->main.next() : pcg->uniform(); }
  double normal(double mean, double sd) { return cpfg ? cpfg->nran(mean, sd) : pcg->normal(mean, sd); }
  /// A uniform draw that is not 0 (cpfg's bran redraws a 0).
  double nonZero() {
    double u;
    do u = uniform();
    while (u == 0);
    return u;
  }
};

/// A draw from the beta(a, b) distribution, by R.C.H. Cheng's rejection algorithm BA
/// ("Generating beta variates with nonintegral shape parameters", CACM 21(4), 1978).
/// NaN for non-positive shapes (the caller reports non-finite values). cpfg's streams draw
/// as cpfg's brand does (each uniform redrawn while 0, no limit on the tries).
inline double betaDraw(Draws& rng, double a, double b) {
  if (!(a > 0) || !(b > 0)) return std::nan("");
  const double alpha = a + b;
  const double beta = std::min(a, b) <= 1 ? std::min(a, b) : std::sqrt((alpha - 2) / (2 * a * b - alpha));
  const double lambda = std::min(a, b) <= 1 ? std::min(a, b) : 1 / beta;
  const double gamma = a + lambda;
  if (rng.cpfg) {
    for (long tries = 0; tries < 100000000; ++tries) {
      const double u1 = rng.nonZero(), u2 = rng.nonZero();
      const double v = (1 / lambda) * std::log(u1 / (1 - u1));
      const double w = a * std::exp(v);
      if (!(alpha * std::log(alpha / (b + w)) + gamma * v - std::log(4.0) < std::log(u1 * u1 * u2))) return w / (b + w);
    }
    return std::nan("");
  }
  for (int tries = 0; tries < 100000; ++tries) {
    double u1 = rng.uniform(), u2 = rng.uniform();
    if (u1 <= 0 || u1 >= 1 || u2 <= 0) continue;
    const double v = std::log(u1 / (1 - u1)) / lambda;
    const double w = a * std::exp(v);
    if (alpha * std::log(alpha / (b + w)) + gamma * v - std::log(4.0) >= std::log(u1 * u1 * u2)) return w / (b + w);
  }
  return std::nan("");
}

/// A draw from the binomial(n, p) distribution: n trials, each a success with probability p.
inline double binomialDraw(Draws& rng, double n, double p) {
  if (!(n >= 0) || n > 1e7) return std::nan("");  // beyond 10^7 trials: a non-finite value
  const long trials = static_cast<long>(n);
  long k = 0;
  for (long t = 0; t < trials; ++t) k += rng.uniform() <= p;
  return static_cast<double>(k);
}

/// One bytecode instruction: push a constant or variable, or pop operands and push a result.
struct Instr {
  Op op = Op::Const;
  uint16_t var = 0;  ///< Var: register index
  double c = 0;      ///< Const: the value
};

/// A range [begin, end) of Program::code.
struct CodeRange {
  uint32_t begin = 0;
  uint32_t end = 0;
  bool empty() const { return begin == end; }
};

/// cpfg's printf to stderr: format (checked by the parser: only numeric conversions, one
/// per value) with the n values args.
void printFormatted(const std::string& format, const double* args, int n);
/// The text printFormatted prints.
std::string formatPrintf(const std::string& format, const double* args, int n);

/// The output instructions of evalCode (`printf` and cpfg's file calls: its cold path):
/// pops their arguments off stack[0, sp), pushes fopen's file number, and returns the new sp.
inline int evalOutput(const Instr& in, double* stack, int sp, const std::vector<std::string>* strings,
                      Effects* effects) {
  const int n = static_cast<int>(in.c);
  CpfgFiles* files = effects ? effects->files : nullptr;
  switch (in.op) {
    case Op::Printf:
      if (strings && in.var < strings->size()) printFormatted((*strings)[in.var], stack + sp - n, n);
      return sp - n;
    case Op::Fopen:
      stack[sp] = files && strings ? files->open((*strings)[in.var], (*strings)[in.var + 1]) : -1;
      return sp + 1;
    case Op::Fprintf:
      if (files && strings) files->print(stack[sp - n - 1], (*strings)[in.var], stack + sp - n, n);
      return sp - n - 1;
    case Op::Fflush:
      if (files) files->flush(stack[sp - 1]);
      return sp - 1;
    case Op::Fclose:
      if (files) files->close(stack[sp - 1]);
      return sp - 1;
    default:
      return sp;
  }
}

/// Evaluates one expression, or runs one statement block (Store, Jz, Jmp write into vars,
/// which must then be writable; jump targets count from code; a block returns 0, or NaN
/// after kMaxLoopJumps backward jumps). rng is used only by the random draws and, for cpfg's
/// streams, `srand` (never null when the code draws: the compiler marks such productions
/// usesRandom). effects, when
/// given, records what `srand` and `stop` ask for; tables are the view file's function and
/// curve files `func` and `curveX...` read (NaN without them).
inline double evalCode(const Instr* code, const Instr* end, const double* vars, Draws* rng,
                       const std::vector<std::string>* strings = nullptr, Effects* effects = nullptr,
                       const CpfgTables* tables = nullptr, double* arrays = nullptr) {
  double stack[kMaxStack];
  int sp = 0;
  long backJumps = 0;
  constexpr double kDeg = kPi / 180.0;
  for (const Instr* in = code; in != end; ++in) {
    switch (in->op) {
      case Op::Const: stack[sp++] = in->c; break;
      case Op::Var: stack[sp++] = vars[in->var]; break;
      case Op::Add: --sp; stack[sp - 1] += stack[sp]; break;
      case Op::Sub: --sp; stack[sp - 1] -= stack[sp]; break;
      case Op::Mul: --sp; stack[sp - 1] *= stack[sp]; break;
      case Op::Div: --sp; stack[sp - 1] /= stack[sp]; break;
      case Op::Pow: case Op::PowFn: --sp; stack[sp - 1] = std::pow(stack[sp - 1], stack[sp]); break;
      case Op::Neg: stack[sp - 1] = -stack[sp - 1]; break;
      case Op::Not: stack[sp - 1] = stack[sp - 1] == 0.0 ? 1.0 : 0.0; break;
      case Op::Lt: --sp; stack[sp - 1] = stack[sp - 1] < stack[sp] ? 1.0 : 0.0; break;
      case Op::Le: --sp; stack[sp - 1] = stack[sp - 1] <= stack[sp] ? 1.0 : 0.0; break;
      case Op::Gt: --sp; stack[sp - 1] = stack[sp - 1] > stack[sp] ? 1.0 : 0.0; break;
      case Op::Ge: --sp; stack[sp - 1] = stack[sp - 1] >= stack[sp] ? 1.0 : 0.0; break;
      case Op::Eq: --sp; stack[sp - 1] = stack[sp - 1] == stack[sp] ? 1.0 : 0.0; break;
      case Op::Ne: --sp; stack[sp - 1] = stack[sp - 1] != stack[sp] ? 1.0 : 0.0; break;
      case Op::And: --sp; stack[sp - 1] = (stack[sp - 1] != 0.0 && stack[sp] != 0.0) ? 1.0 : 0.0; break;
      case Op::Or: --sp; stack[sp - 1] = (stack[sp - 1] != 0.0 || stack[sp] != 0.0) ? 1.0 : 0.0; break;
      case Op::Sin: stack[sp - 1] = std::sin(stack[sp - 1] * kDeg); break;
      case Op::Cos: stack[sp - 1] = std::cos(stack[sp - 1] * kDeg); break;
      case Op::Tan: stack[sp - 1] = std::tan(stack[sp - 1] * kDeg); break;
      case Op::Asin: stack[sp - 1] = std::asin(stack[sp - 1]) / kDeg; break;
      case Op::Acos: stack[sp - 1] = std::acos(stack[sp - 1]) / kDeg; break;
      case Op::Atan: stack[sp - 1] = std::atan(stack[sp - 1]) / kDeg; break;
      case Op::Atan2: --sp; stack[sp - 1] = std::atan2(stack[sp - 1], stack[sp]) / kDeg; break;
      case Op::Sqrt: stack[sp - 1] = std::sqrt(stack[sp - 1]); break;
      case Op::Exp: stack[sp - 1] = std::exp(stack[sp - 1]); break;
      case Op::Log: stack[sp - 1] = std::log(stack[sp - 1]); break;
      case Op::Abs: stack[sp - 1] = std::fabs(stack[sp - 1]); break;
      case Op::Min: --sp; stack[sp - 1] = std::fmin(stack[sp - 1], stack[sp]); break;
      case Op::Max: --sp; stack[sp - 1] = std::fmax(stack[sp - 1], stack[sp]); break;
      case Op::Floor: stack[sp - 1] = std::floor(stack[sp - 1]); break;
      case Op::Ceil: stack[sp - 1] = std::ceil(stack[sp - 1]); break;
      case Op::Sign: stack[sp - 1] = stack[sp - 1] > 0 ? 1.0 : (stack[sp - 1] < 0 ? -1.0 : 0.0); break;
      case Op::Ran: stack[sp - 1] = rng->uniform() * stack[sp - 1]; break;
      case Op::Nran: --sp; stack[sp - 1] = rng->normal(stack[sp - 1], stack[sp]); break;
      case Op::Select: sp -= 2; stack[sp - 1] = stack[sp - 1] != 0.0 ? stack[sp] : stack[sp + 1]; break;
      case Op::Round: stack[sp - 1] = std::floor(stack[sp - 1] + 0.5); break;
      case Op::Rem: {
        --sp;
        const double a = std::trunc(stack[sp - 1]), b = std::trunc(stack[sp]);
        stack[sp - 1] = b == 0.0 || !std::isfinite(a) ? std::nan("") : std::fmod(a, b);
        break;
      }
      case Op::Bran: --sp; stack[sp - 1] = betaDraw(*rng, stack[sp - 1], stack[sp]); break;
      case Op::Biran: --sp; stack[sp - 1] = binomialDraw(*rng, stack[sp - 1], stack[sp]); break;
      case Op::Store: const_cast<double*>(vars)[in->var] = stack[--sp]; break;
      case Op::Jz:
        if (stack[--sp] != 0.0) break;
        [[fallthrough]];
      case Op::Jmp: {
        const Instr* to = code + static_cast<ptrdiff_t>(in->c);
        if (to <= in && ++backJumps > kMaxLoopJumps) return std::nan("");
        in = to - 1;  // the loop's ++in lands on the target
        break;
      }
      case Op::Srand:
        if (rng && rng->cpfg) {
          rng->cpfg->srand(stack[sp - 1]);  // cpfg's stream: reseeded at once, for the draws after it
        } else if (effects) {
          effects->reseed = true;
          effects->seed = stack[sp - 1];
        }
        stack[sp - 1] = 0.0;
        break;
      case Op::Stop:
        if (effects) effects->stop = true;
        stack[sp - 1] = 0.0;
        break;
      case Op::Func:
        stack[sp - 1] = tables && in->var < tables->functions.size() ? tables->functions[in->var].value(stack[sp - 1]) : std::nan("");
        break;
      case Op::Curve:
        stack[sp - 1] = tables && in->var < tables->curves.size()
                            ? tables->curves[in->var].atLength(stack[sp - 1])[static_cast<int>(in->c) % 3]
                            : std::nan("");
        break;
      case Op::CurveLength:
        stack[sp++] = tables && in->var < tables->curves.size() ? tables->curves[in->var].length() : std::nan("");
        break;
      case Op::ArrayAt: {
        const CpfgArray& a = tables->arrays[in->var];
        const int d = static_cast<int>(in->c);
        const double i = std::trunc(stack[sp - 1]);
        if (!(i >= 0 && i < a.dims[d])) arrayIndexError(a, d, stack[sp - 1]);
        stack[sp - 1] = i;
        break;
      }
      case Op::ArrayLoad:
        stack[sp - 1] = arrays ? arrays[tables->arrays[in->var].offset + static_cast<uint32_t>(stack[sp - 1])] : std::nan("");
        break;
      case Op::ArrayStore:
        sp -= 2;
        arrays[tables->arrays[in->var].offset + static_cast<uint32_t>(stack[sp])] = stack[sp + 1];
        break;
      case Op::Printf: case Op::Fopen: case Op::Fprintf: case Op::Fflush: case Op::Fclose:
        sp = evalOutput(*in, stack, sp, strings, effects);
        break;
    }
  }
  return sp > 0 ? stack[sp - 1] : 0.0;
}

/// How one successor parameter is computed.
enum class ArgKind : uint8_t { Const, Var, VarAddConst, VarMulConst, VarDivConst, Expr };

struct Arg {
  ArgKind kind = ArgKind::Const;
  uint16_t var = 0;
  double c = 0;
  CodeRange code;  ///< Expr only
};

/// One module of a successor template: its symbol and its arguments
/// Production::args[firstArg .. firstArg + argCount).
struct SuccModule {
  SymbolId symbol = 0;
  uint16_t argCount = 0;
  uint32_t firstArg = 0;
};

/// One item of a context pattern: a symbol with its formal parameters, or a bracket.
struct PatternItem {
  SymbolId symbol = 0;
  uint16_t paramCount = 0;
  uint16_t firstVar = 0;  ///< register of its first formal parameter
  bool openBracket = false;
  bool closeBracket = false;
  /// cpfg's `=` in a right context (generate.c, RconDiff): the match moves to the `]` that
  /// closes the current branch (or the end of the string) without consuming it.
  bool skipBranch = false;
};

/// One compiled production `lc < pred > rc : cond --> succ : weight`.
struct Production {
  SourceLoc loc;          ///< position of the predecessor
  std::string text;       ///< the predecessor as written (for messages)
  std::string sourceLine; ///< the production's line (for messages)
  SymbolId predecessor = 0;
  uint16_t predParams = 0;
  uint16_t predFirstVar = 0;
  /// cpfg's predecessors of several modules: the modules after the first, matched at the
  /// positions right after it (no skipping); the production replaces them all.
  std::vector<PatternItem> predRest;
  std::vector<PatternItem> left;   ///< in textual order
  std::vector<PatternItem> right;  ///< in textual order
  CodeRange condition;             ///< empty: always true
  CodeRange before;                ///< cpfg's statements before the condition (`{ ... } cond`)
  CodeRange after;                 ///< cpfg's statements after it (`cond { ... }`), run when the production applies
  uint16_t localFirst = 0;         ///< registers of the statements' local variables (zeroed before `before`)
  uint16_t localCount = 0;
  bool hasStatements() const { return !before.empty() || !after.empty(); }
  std::vector<SuccModule> successor;
  std::vector<Arg> args;
  bool stochastic = false;
  double weight = 1;
  bool usesRandom = false;  ///< condition or successor calls ran/nran
  bool simpleCtx = false;   ///< simpleContext(), cached by RuleSet::finalize()
  /// True when matching looks at other modules than the predecessor's first (contexts, or
  /// a predecessor of several modules).
  bool hasContext() const { return !left.empty() || !right.empty() || !predRest.empty(); }
  /// Contexts of at most one symbol on each side (no brackets): matched against the
  /// cached neighbours directly.
  bool simpleContext() const {
    auto plain = [](const std::vector<PatternItem>& v) {
      return v.size() <= 1 && (v.empty() || (!v[0].openBracket && !v[0].closeBracket && !v[0].skipBranch));
    };
    return plain(left) && plain(right) && predRest.empty();
  }
};

/// Per predecessor symbol: its productions and what the size pass may assume.
struct SymbolRules {
  const Production* simple = nullptr;  ///< the only production, context-free, unconditional, deterministic
  uint32_t maxModules = 1;             ///< most modules any of its successors (or a copy) writes
  uint32_t maxParams = 0;              ///< most parameters any of its successors writes
  uint32_t count = 0;                  ///< number of productions with this predecessor
  int32_t dispatch = -1;               ///< index into RuleSet::dispatches, or -1
};

/// Context dispatch for a predecessor whose productions are all parameterless, unconditional,
/// deterministic and have at most one symbol of context per side (ABOP 1.31-style signal
/// grammars): the production is looked up from the two neighbours' symbols in one step.
struct ContextDispatch {
  std::vector<uint16_t> index;    ///< per symbol: 1 + its rank among context symbols, 0 if unused
  uint32_t width = 1;             ///< context symbols + 1
  std::vector<int32_t> table;     ///< [leftIndex * width + rightIndex] -> production, -1 none
};

/// A block of productions with a lookup table by predecessor symbol.
struct RuleSet {
  std::vector<Production> productions;
  /// bySymbol[s] lists indices into productions whose predecessor is s, in file order.
  std::vector<std::vector<uint32_t>> bySymbol;
  std::vector<SymbolRules> rules;  ///< per symbol (filled by finalize())
  std::vector<ContextDispatch> dispatches;
  /// Fills rules from productions and bySymbol.
  void finalize() {
    for (Production& p : productions) p.simpleCtx = p.simpleContext();
    rules.assign(bySymbol.size(), {});
    dispatches.clear();
    for (size_t s = 0; s < bySymbol.size(); ++s) {
      SymbolRules& r = rules[s];
      r.count = static_cast<uint32_t>(bySymbol[s].size());
      for (uint32_t idx : bySymbol[s]) {
        const Production& p = productions[idx];
        r.maxModules = std::max<uint32_t>(r.maxModules, static_cast<uint32_t>(p.successor.size()));
        r.maxParams = std::max<uint32_t>(r.maxParams, static_cast<uint32_t>(p.args.size()));
      }
      if (bySymbol[s].size() == 1) {
        const Production& p = productions[bySymbol[s][0]];
        if (!p.hasContext() && p.condition.empty() && !p.stochastic && !p.hasStatements()) r.simple = &p;
      }
      if (!r.simple && r.count) buildDispatch(s, r);
    }
  }
  void buildDispatch(size_t s, SymbolRules& r) {
    ContextDispatch d;
    d.index.assign(bySymbol.size(), 0);
    std::vector<SymbolId> used;
    for (uint32_t idx : bySymbol[s]) {
      const Production& p = productions[idx];
      if (!p.simpleCtx || !p.condition.empty() || p.stochastic || p.predParams || p.hasStatements()) return;
      for (const auto* side : {&p.left, &p.right})
        for (const PatternItem& it : *side) {
          if (it.paramCount) return;
          if (!d.index[it.symbol]) {
            used.push_back(it.symbol);
            d.index[it.symbol] = static_cast<uint16_t>(used.size());
          }
        }
    }
    d.width = static_cast<uint32_t>(used.size()) + 1;
    d.table.assign(static_cast<size_t>(d.width) * d.width, -1);
    for (uint32_t li = 0; li < d.width; ++li)
      for (uint32_t ri = 0; ri < d.width; ++ri)
        for (uint32_t idx : bySymbol[s]) {
          const Production& p = productions[idx];
          bool leftOk = p.left.empty() || (li && d.index[p.left[0].symbol] == li);
          bool rightOk = p.right.empty() || (ri && d.index[p.right[0].symbol] == ri);
          if (leftOk && rightOk) {
            d.table[li * d.width + ri] = static_cast<int32_t>(idx);
            break;
          }
        }
    r.dispatch = static_cast<int32_t>(dispatches.size());
    dispatches.push_back(std::move(d));
  }

  int maxDepth = 1;  ///< decomposition / interpretation recursion depth
  bool anyContext = false;
  bool empty() const { return productions.empty(); }
};

/// One of cpfg's sub-L-systems (`lsystem: n` after the main one's `endlsystem`): its
/// productions rewrite the modules between a `?(n, scale)` and its `$`, its decomposition
/// rules decompose what they write there, its interpretation rules draw the modules the
/// turtle reaches inside the call, and its `ignore:`/`consider:` table is the one context
/// matching uses there (generate.c, Derive and ApplyProd; interpret.c, InterpretHomomorphism).
struct SubLsystem {
  double id = 0;           ///< n
  SourceLoc loc;           ///< its `lsystem:` header
  std::string sourceLine;
  RuleSet productions;
  RuleSet decomposition;
  RuleSet interpretation;
  std::vector<uint8_t> ignored;  ///< per symbol: skipped by context matching inside its calls
};

/// A compiled grammar.
struct Program {
  std::string fileName;
  std::string name;
  int derivationLength = 0;
  uint64_t seed = 0;
  /// The file has a `seed:` line: in cpfg's notation this makes the L-system stochastic
  /// (without it cpfg applies the first applicable production, whatever its weight).
  bool hasSeed = false;
  /// The seed comes from GrammarOverrides (`--seed`), not from the file.
  bool seedOverridden = false;
  bool hasAngle = false;
  double angleDeg = 0;
  Dialect dialect = Dialect::Sprig;  ///< the notation the file is read in (by its extension)
  /// cpfg's notation: module parameters are 32-bit floats, as cpfg's string stores them
  /// (generate.c, AppendParameter), while expressions compute in double as cpfg's Eval
  /// does: every parameter written into a string (axiom, successors, decomposition,
  /// interpretation, query modules) is rounded to the nearest float.
  bool floatParams = false;
  /// True when the axiom or a successor turns without an angle (`+`, `&`, ...), so that
  /// the default angle matters.
  bool bareTurn = false;
  /// cpfg's global variables, in order of first assignment in the blocks below: global k
  /// is register k while a block runs, and register kMaxVars - 1 - k of every production.
  std::vector<std::string> globals;
  /// cpfg's notation: a production or decomposition rule assigns a global in its
  /// statements; the modules after it read the new value (cpfg rewrites left to right).
  bool rulesAssignGlobals = false;
  /// cpfg's `ring lsystem`: context matching joins the ends of the string (the first
  /// module's left neighbour is the last module, and the other way round).
  bool ring = false;
  /// Per symbol (empty: none): a cpfg command (`@o`) that a production written for its
  /// last letter rewrites (GrammarParser::checkSplitCommands); cpfg visits its characters
  /// one by one, the letter last, each taking a choice draw.
  std::vector<uint8_t> splitCommand;
  /// cpfg's notation: axiom parameters that read global variables (index into
  /// axiom.params, code), evaluated after the `Start:` block as cpfg's Rewind does.
  std::vector<std::pair<uint32_t, CodeRange>> axiomDeferred;
  /// cpfg's blocks: `Start:` (before the derivation), `StartEach:` and `EndEach:` (around
  /// every step), `End:` (after the last step).
  CodeRange startBlock, startEachBlock, endEachBlock, endBlock;
  SymbolTable symbols;
  ModuleString axiom;
  std::vector<std::pair<std::string, double>> defines;
  std::vector<Instr> code;
  std::vector<std::string> strings;  ///< printf formats (Instr::var of Op::Printf)
  CpfgTables cpfg;  ///< the view file's function and curve files (`func(n, x)`, `curveX(n, t)`)
  RuleSet productions;
  RuleSet decomposition;
  RuleSet interpretation;
  /// cpfg's sub-L-systems, in file order (empty for most grammars; only in cpfg's notation).
  std::vector<SubLsystem> subLsystems;
  /// True when the main L-system or a sub-L-system has interpretation rules.
  bool anyInterpretation() const {
    if (!interpretation.empty()) return true;
    for (const SubLsystem& sub : subLsystems)
      if (!sub.interpretation.empty()) return true;
    return false;
  }
  /// The main L-system's number (its `lsystem:` label, when a number): `?(n, s)` with this
  /// n calls the main productions again.
  std::optional<double> mainLsystemId;
  /// `?` (the sub-L-system call, when the file writes it) and `$` (its end).
  std::optional<SymbolId> subCall;
  SymbolId subEnd = 0;
  std::vector<uint8_t> ignored;  ///< per symbol: skipped by context matching
  SymbolId openBracket = 0, closeBracket = 0, cut = 0;
  /// True when some successor or the axiom contains the cut symbol `%`.
  bool usesCut = false;
  /// True when the axiom or a production writes one of cpfg's query modules (`?P ?H ?L ?U`):
  /// the Deriver then interprets the string before every step and writes the turtle's
  /// state into their parameters.
  bool usesQuery = false;
  /// True when the grammar writes cpfg's `?E` (communication with an environmental program).
  bool usesEnvQuery = false;
  /// The `derivation length:` header (line 0 when the file has none), with its line's text;
  /// module-limit errors point here when the grammar's own length is used.
  SourceLoc lengthLoc;
  std::string lengthLine;
  /// The warnings and notes of parsing (a likely undeclared module name, an overridden
  /// `derivation length:`), in file order; errors are thrown instead.
  std::vector<Diagnostic> warnings;
  /// The `axiom:` header and its line's text; module-limit errors point here when the
  /// number of steps comes from elsewhere (an override, --steps).
  SourceLoc axiomLoc;
  std::string axiomLine;
};

}  // namespace sprig::lsystem::detail
