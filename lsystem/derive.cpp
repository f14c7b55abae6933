#include "lsystem/derive.h"

#include <algorithm>
#include <memory>
#include <filesystem>
#include <charconv>
#include <cstring>
#include <limits>
#include <cmath>
#include <optional>
#include <unordered_map>

#include "core/rng.h"
#include "lsystem/detail/overwrite.h"
#include "lsystem/detail/program.h"
#include "lsystem/view_file.h"

namespace sprig::lsystem {

using detail::Arg;
using detail::ArgKind;
using detail::Instr;
using detail::PatternItem;
using detail::Production;
using detail::Program;
using detail::RuleSet;
using detail::SuccModule;

namespace {

std::string numberText(double v) {
  if (std::isnan(v)) return "nan";
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

/// Writes modules into a ModuleString through raw pointers, growing it geometrically and
/// never past the module limit.
class Writer {
 public:
  /// Starts writing s from empty, with room for at least modules and params.
  /// limitAt is where a limit error points (its message is ignored).
  Writer(ModuleString& s, bool births, size_t maxModules, const Diagnostic& limitAt, int step, size_t modules, size_t params)
      : s_(s), births_(births), maxModules_(maxModules), limitAt_(limitAt), step_(step) {
    // Only the reserved part is sized (and zero-filled where new): sizing to the whole
    // capacity would cost O(largest string) per step.
    // The string is rewritten from scratch: growing buffers drop, not copy, the old
    // contents (detail/overwrite.h).
    detail::resizeForOverwrite(s_.symbols, std::max(modules, size_t(16)));
    detail::resizeForOverwrite(s_.offsets, s_.symbols.size() + 1);
    detail::resizeForOverwrite(s_.params, std::max(params, size_t(16)));
    if (births_) detail::resizeForOverwrite(s_.birthSteps, s_.symbols.size());
    else s_.birthSteps.clear();
    refresh();
    off_[0] = 0;
  }

  /// Makes room for m more modules and p more parameters.
  void reserve(size_t m, size_t p) {
    if (n_ + m > capM_) [[unlikely]] growModules(n_ + m);
    if (np_ + p > capP_) [[unlikely]]
      growParams(np_ + p);
  }

  /// Appends a module whose parameters the caller writes next with param().
  void begin(SymbolId s, int32_t birth) {
    sym_[n_] = s;
    if (births_) birth_[n_] = birth;
  }
  void param(double v) { par_[np_++] = v; }
  void end() { off_[++n_] = static_cast<uint32_t>(np_); }

  /// Appends a module with parameters p (room must be reserved).
  void copy(SymbolId s, const double* p, uint32_t count, int32_t birth) {
    begin(s, birth);
    for (uint32_t k = 0; k < count; ++k) par_[np_ + k] = p[k];
    np_ += count;
    end();
  }

  /// Appends the m modules whose symbols start at s and offsets at o (into pars), and their
  /// birth steps when tracked: one bulk copy for a run of modules no production touches.
  void copyRun(const SymbolId* s, const uint32_t* o, const double* pars, size_t m, const int32_t* births) {
    uint32_t pb = o[0], pe = o[m];
    reserve(m, pe - pb);
    if (m == 0) return;
    std::memcpy(sym_ + n_, s, m * sizeof(SymbolId));
    if (births_) std::memcpy(birth_ + n_, births, m * sizeof(int32_t));
    // pars may be null (a string without parameters): memcpy's pointers must not be.
    if (pe > pb) std::memcpy(par_ + np_, pars + pb, (pe - pb) * sizeof(double));
    const uint32_t delta = static_cast<uint32_t>(np_) - pb;  // modular: offsets stay below 2^32
    for (size_t k = 1; k <= m; ++k) off_[n_ + k] = o[k] + delta;
    n_ += m;
    np_ += pe - pb;
  }

  size_t modules() const { return n_; }

  /// Shrinks the string to what was written.
  void finish() {
    s_.symbols.resize(n_);
    s_.offsets.resize(n_ + 1);
    s_.params.resize(np_);
    if (births_) s_.birthSteps.resize(n_);
  }

  [[noreturn]] static void overLimit(size_t maxModules, const Diagnostic& at, int step) {
    throw InputError(at.loc, "derivation would exceed " + std::to_string(maxModules) + " modules at step " + std::to_string(step),
                     at.sourceLine);
  }

 private:
  void refresh() {
    sym_ = s_.symbols.data();
    off_ = s_.offsets.data();
    par_ = s_.params.data();
    birth_ = s_.birthSteps.data();
    capM_ = s_.symbols.size();
    capP_ = s_.params.size();
  }

  void growModules(size_t need) {
    if (need > maxModules_) overLimit(maxModules_, limitAt_, step_);
    size_t cap = std::min(maxModules_, std::max(need, capM_ * 2));
    s_.symbols.resize(cap);
    s_.offsets.resize(cap + 1);
    if (births_) s_.birthSteps.resize(cap);
    refresh();
    capP_ = s_.params.size();
  }

  void growParams(size_t need) {
    constexpr size_t kMaxParams = std::numeric_limits<uint32_t>::max();  // offsets are 32-bit
    if (need > kMaxParams)
      throw InputError(limitAt_.loc,
                       "derivation would exceed " + std::to_string(kMaxParams) + " parameters at step " + std::to_string(step_),
                       limitAt_.sourceLine);
    s_.params.resize(std::min(kMaxParams, std::max(need, capP_ * 2)));
    refresh();
  }

  ModuleString& s_;
  bool births_;
  size_t maxModules_;
  const Diagnostic& limitAt_;
  int step_;
  SymbolId* sym_ = nullptr;
  uint32_t* off_ = nullptr;
  double* par_ = nullptr;
  int32_t* birth_ = nullptr;
  size_t n_ = 0, np_ = 0, capM_ = 0, capP_ = 0;
};

}  // namespace

/// Decomposition nested deeper than this (a `maximum depth` above it that the rules reach)
/// is an error: the levels are kept on an explicit stack, one frame each (docs/GRAMMAR.md).
constexpr int kMaxDecompositionNesting = 100000;

/// Stream id of the random draws of cpfg's Start/StartEach/EndEach/End blocks (with the step).
constexpr uint64_t kBlockStream = 0xfffffffffffe0000ull;

struct Deriver::Impl {
  Grammar grammar;  // keeps the program alive
  const Program* prog = nullptr;
  DeriveOptions opt;
  int steps = 0;
  int baseSteps = 0;  ///< steps before any `stop`: restart() begins with it again
  uint64_t seed = 0;
  int done = 0;
  uint64_t written = 0;
  ModuleString cur, next;
  std::vector<int32_t> match;  ///< bracket partner per module (context-sensitive grammars)
  /// Where module-limit errors point: the grammar's `derivation length:` when it sets the
  /// number of steps, else its axiom, else just the file.
  Diagnostic limitAt;

  void locateLimit() {
    limitAt = Diagnostic{};
    bool ownLength = !opt.steps && prog->lengthLoc.line > 0;
    limitAt.loc = ownLength ? prog->lengthLoc : prog->axiomLoc;
    limitAt.sourceLine = ownLength ? prog->lengthLine : prog->axiomLine;
    if (limitAt.loc.file.empty()) limitAt.loc.file = prog->fileName;
  }

  // Per-module random stream, created on first use.
  Rng rng;
  bool rngReady = false;
  uint64_t rngStream = 0, rngItem = 0;
  detail::Draws draws;
  /// cpfg's notation: cpfg's own sequential streams (detail::CpfgRandom) replace the
  /// per-module ones (a step visits the modules in string order, on one thread), and the
  /// local variables of a production's statements keep their values from one application
  /// to the next (cpfg's are the production's own symbols: generate.c, CreateVarTable
  /// binds only the formal parameters).
  bool cpfgSemantics = false;
  /// cpfg's notation: the local variables of each production with statements, between uses.
  std::unordered_map<const Production*, std::vector<double>> cpfgLocals;
  detail::CpfgRandom cpfgRandom;
  /// cpfg's stochastic choice for the module being rewritten: its drand48 draw, or -1
  /// (not a production step of a stochastic L-system: the first applicable production).
  double choiceDraw = -1;
  /// Vars of each applicable production (cpfg's choice among productions with statements).
  std::vector<double> candidateVars;

  /// The turtle that fills query modules (made on first use).
  std::unique_ptr<Turtle> queryTurtle;
  /// The current string's query modules wait for the next step to fill them
  /// (DeriveOptions::queriesAfterLastStep).
  bool queriesPending = false;

  /// After step `stepDone` (0: the axiom): fills the query modules, or, for the last step
  /// when cpfg -g would not draw it, leaves them to the next step.
  void queriesAfter(int stepDone) {
    queriesPending = !opt.queriesAfterLastStep && stepDone >= steps;
    const bool env = environmentActive() && (opt.environmentAfterEachStep || stepDone < steps);
    environmentDone = false;
    if (env) queriesPending = false;  // cpfg's environment pass fills the query modules too
    if (!queriesPending) fillQueries(env);
  }

  /// The grammar writes `?E` modules and an environmental program is running.
  bool environmentActive() const { return opt.environment && prog->usesEnvQuery; }
  /// The current string's `?E` modules were exchanged with the environmental program.
  bool environmentDone = false;

  /// cpfg's query modules: interprets cur (through the interpretation rules, which hold
  /// no query module) and writes the turtle's frame at each query module it reaches into
  /// that module's parameters. Query modules pass through the interpretation rules
  /// unchanged and in order, so the k-th one of the interpreted string is the k-th of cur.
  void fillQueries(bool exchange = false) {
    if (!prog->usesQuery && !exchange) return;
    if (!queryTurtle) {
      TurtleSettings t;
      if (opt.queryTurtle) {
        t = *opt.queryTurtle;
      } else {
        if (prog->dialect == detail::Dialect::Cpfg) t = cpfgTurtleSettings(nullptr, t);
        t.angleDeg = prog->hasAngle ? prog->angleDeg : kCpfgDefaultAngleDeg;
      }
      t.growthStep = -1;
      t.checkTextures = false;  // nothing is drawn: an unknown texture selects none, as in cpfg
      queryTurtle = std::make_unique<Turtle>(prog->symbols, t);
    }
    std::vector<Turtle::QueryHit> hits;
    if (!prog->anyInterpretation()) {
      hits = queryTurtle->query(cur);
    } else {
      ModuleString shown = interpreted(cur, done);
      hits = queryTurtle->query(shown);
      // Index of the k-th query module of shown -> k-th of cur.
      std::vector<size_t> curQueries, shownOrdinal(shown.size(), 0);
      for (size_t i = 0; i < cur.size(); ++i)
        if (queryTurtle->commandOf(cur.symbols[i]) == Turtle::Command::Query) curQueries.push_back(i);
      size_t k = 0;
      for (size_t i = 0; i < shown.size(); ++i)
        if (queryTurtle->commandOf(shown.symbols[i]) == Turtle::Command::Query) shownOrdinal[i] = k++;
      for (Turtle::QueryHit& h : hits) h.index = curQueries[shownOrdinal[h.index]];
    }
    if (exchange) exchangeEnvironment(hits);
    for (const Turtle::QueryHit& h : hits) {
      const std::string& name = prog->symbols.name(cur.symbols[h.index]);
      if (name == "?E") continue;
      DVec3 v = name == "?P" ? h.frame.position : name == "?H" ? h.frame.heading : name == "?L" ? h.frame.left : -h.frame.up;
      const uint32_t count = std::min<uint32_t>(cur.paramCount(h.index), 3);
      double* p = cur.params.data() + cur.offsets[h.index];
      for (uint32_t c = 0; c < count; ++c)
        p[c] = prog->floatParams ? static_cast<double>(static_cast<float>(v[static_cast<int>(c)])) : v[static_cast<int>(c)];
    }
  }

  /// cpfg's `?E` exchange (interpret.c, case '?'; comm_master.c): every `?E` the turtle
  /// reached is sent with its distance in cpfg's string (one byte per symbol character,
  /// 1 + 5 bytes per parameter: '(' or ',' and a float), counted from the first `?E`, the
  /// module after it and the turtle in floats; the answers set the parameters they name.
  void exchangeEnvironment(const std::vector<Turtle::QueryHit>& hits) {
    environmentDone = true;
    std::vector<uint64_t> at(cur.size() + 1, 0);  // cpfg's byte offset of each module
    for (size_t i = 0; i < cur.size(); ++i) {
      const uint32_t k = cur.paramCount(i);
      at[i + 1] = at[i] + prog->symbols.name(cur.symbols[i]).size() + (k ? 1 + 5 * uint64_t{k} : 0);
    }
    std::vector<EnvironmentQuery> queries;
    std::unordered_map<uint64_t, size_t> moduleAt;  // distance -> index in cur
    auto floats = [&](size_t i) {
      std::vector<float> v(cur.paramCount(i));
      for (size_t c = 0; c < v.size(); ++c) v[c] = static_cast<float>(cur.params[cur.offsets[i] + c]);
      return v;
    };
    auto vec = [](const DVec3& v) {
      return std::array<float, 3>{static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z)};
    };
    for (const Turtle::QueryHit& h : hits) {
      if (prog->symbols.name(cur.symbols[h.index]) != "?E") continue;
      EnvironmentQuery q;
      if (queries.empty()) firstEnv = h.index;
      q.distance = at[h.index] - at[firstEnv];
      q.params = floats(h.index);
      if (h.index + 1 < cur.size()) {
        // cpfg's symbol of the next module: its first character (two after '@' or '~'),
        // with the parameters when that is the whole name (cpfg's '@Gs(..)' is '@', 'G', 's(..)')
        const std::string& n = prog->symbols.name(cur.symbols[h.index + 1]);
        const size_t len = (n[0] == '@' || n[0] == '~') && n.size() > 1 ? 2 : 1;
        q.next = n.substr(0, len);
        if (len == n.size()) q.nextParams = floats(h.index + 1);
      }
      q.position = vec(h.frame.position);
      q.heading = vec(h.frame.heading);
      q.left = vec(h.frame.left);
      q.up = vec(-h.frame.up);  // cpfg's up vector
      moduleAt[q.distance] = h.index;
      queries.push_back(std::move(q));
    }
    for (const EnvironmentAnswer& a : opt.environment->exchange(queries, done)) {
      if (a.distance == 1 && !moduleAt.count(1)) continue;  // cpfg: a ?E of an interpretation rule
      auto it = moduleAt.find(a.distance);
      if (it == moduleAt.end())
        throw InputError(SourceLoc{"sprig", 0, 0}, "environmental program '" + opt.environment->name() +
                                                        "' answered for the module at distance " + std::to_string(a.distance) +
                                                        ", which is no ?E module it was sent");
      const size_t i = it->second;
      const size_t n = std::min<size_t>(a.params.size(), cur.paramCount(i));  // cpfg sets those that fit
      for (size_t c = 0; c < n; ++c)
        if (a.params[c]) cur.params[cur.offsets[i] + c] = static_cast<double>(*a.params[c]);
    }
  }
  size_t firstEnv = 0;  ///< the first `?E` of the pass (cpfg's first_comm_symbol)

  /// s rewritten by the interpretation rules (recursively up to their maximum depth), as
  /// the turtle reads it; random draws from the interpretation stream of step `step`.
  ModuleString interpreted(const ModuleString& s, int step) const {
    Impl tmp;
    tmp.prog = prog;
    tmp.ignoredTab = prog->ignored.data();
    tmp.seed = seed;
    tmp.opt.maxModules = opt.maxModules;
    tmp.limitAt = limitAt;
    tmp.opt.trackBirthSteps = s.hasBirthSteps();
    tmp.cur = s;
    tmp.globals = globals;
    tmp.arrays = arrays;
    // cpfg's interpretation draws from a copy of the main stream (it never advances the
    // derivation's: cpfg's depends on when it draws, docs/GRAMMAR.md).
    tmp.cpfgSemantics = cpfgSemantics;
    tmp.cpfgRandom = cpfgRandom;
    tmp.cpfgLocals = cpfgLocals;
    // cpfg's interpretation rules that draw (or srand) run depth first, as cpfg's do, so
    // that they draw in cpfg's order.
    const bool cpfgDraws = cpfgSemantics && std::any_of(prog->interpretation.productions.begin(), prog->interpretation.productions.end(),
                                                        [](const Production& p) { return p.usesRandom; });
    if (!prog->subLsystems.empty() || cpfgDraws) {
      ModuleString out;
      Writer w(out, s.hasBirthSteps(), opt.maxModules, limitAt, step, s.size() + 16, s.params.size() + 16);
      tmp.homomorphismWithSubLsystems(s, w, step);
      w.finish();
      return out;
    }
    // Interpretation recursion: depth 1 is one rewrite; deeper levels rewrite what the
    // previous level produced (modules no rule matches stay as they are).
    const RuleSet& rs = prog->interpretation;
    // With predecessors of several modules, matching follows cpfg's depth-first recursion
    // (interpret.c, InterpretHomomorphism): at a deeper level such a predecessor matches
    // only modules of one successor, and a module no rule matched is drawn as it is, never
    // rewritten at a later level. Each module then carries the successor it belongs to.
    const bool multi = std::any_of(rs.productions.begin(), rs.productions.end(), [](const Production& p) { return !p.predRest.empty(); });
    std::vector<uint32_t> segIn, segOut;
    if (multi) {
      segIn.assign(tmp.cur.size(), 0);
      tmp.segIn = &segIn;
      tmp.segOut = &segOut;
    }
    for (int depth = 0; depth < rs.maxDepth; ++depth) {
      bool any = false;
      for (size_t i = 0; i < tmp.cur.size(); ++i)
        if (!rs.bySymbol[tmp.cur.symbols[i]].empty() && (!multi || segIn[i] != kFrozen)) {
          any = true;
          break;
        }
      if (!any) break;
      tmp.rewrite(rs, step, kInterpretStream - static_cast<uint64_t>(depth), false);
      if (multi) std::swap(segIn, segOut);
    }
    return std::move(tmp.cur);
  }

  /// Interpretation with predecessors of several modules (interpreted()): the successor
  /// each module of cur belongs to (kFrozen: a module no rule matched), and the same for
  /// the string rewrite() writes.
  static constexpr uint32_t kFrozen = std::numeric_limits<uint32_t>::max();
  const std::vector<uint32_t>* segIn = nullptr;
  std::vector<uint32_t>* segOut = nullptr;

  /// cpfg's global variables (Program::globals), kMaxVars registers.
  std::vector<double> globals;
  /// The elements of cpfg's `define:` arrays (Program::cpfg.arrayInit at the start).
  std::vector<double> arrays;
  /// What cpfg's `stop` and `srand` asked for (the stop flag is cleared at each start).
  detail::Effects effects;
  /// cpfg's fopen files, in the grammar's folder (Effects::files of the blocks).
  std::unique_ptr<detail::CpfgFiles> files = std::make_unique<detail::CpfgFiles>();
  /// The seed before any `srand` (options or grammar): restart() begins with it again.
  uint64_t baseSeed = 0;
  /// Steps completed at the last `srand`: step k draws from stream k - streamBase.
  int streamBase = 0;

  /// Runs one of cpfg's Start/StartEach/EndEach/End blocks on the globals; its random draws
  /// come from a stream of their own for each step.
  /// stepsBefore: the steps completed when the block runs (for `srand`).
  void runBlock(const detail::CodeRange& r, int step, int stepsBefore) {
    if (r.empty()) return;
    Rng blockRng(deriveSeed(seed, {kBlockStream, static_cast<uint64_t>(step)}));
    detail::Draws blockDraws{&blockRng, nullptr};
    if (cpfgSemantics) blockDraws = {nullptr, &cpfgRandom};
    const Instr* code = prog->code.data();
    const bool looped = std::isnan(
        detail::evalCode(code + r.begin, code + r.end, globals.data(), &blockDraws, &prog->strings, &effects, &prog->cpfg,
                         arrays.data()));
    if (effects.reseed) {
      // cpfg's srand(s): the next step draws as the first step of a derivation with seed s.
      seed = static_cast<uint64_t>(static_cast<int64_t>(std::clamp(effects.seed, -9.2e18, 9.2e18)));
      streamBase = stepsBefore;
      effects.reseed = false;
    }
    if (looped)
      throw InputError(SourceLoc{prog->fileName, 0, 0}, "a Start/StartEach/EndEach/End block loops more than " +
                                                            std::to_string(detail::kMaxLoopJumps) + " times at step " +
                                                            std::to_string(step));
  }

  /// cpfg's string holds one character per module of its own (`@v` is '@' then 'v'), and
  /// a step that rewrites no predecessor at a character copies that character alone, so
  /// every character takes its own choice draw: a module of several characters that no
  /// production rewrites takes one more draw per character after its first (one draw in
  /// all when a production or, as assumed here, a decomposition rule `decomp` rewrites it).
  void copiedCharacterDraws(SymbolId sym, const RuleSet* decomp) {
    if (decomp && !decomp->bySymbol[sym].empty()) return;
    for (size_t k = 1; k < prog->symbols.name(sym).size(); ++k) cpfgRandom.choice.next();
  }

  /// cpfg's L-system is stochastic when the file has a `seed:` line (or a seed is given).
  bool stochasticCpfg() const { return prog->hasSeed || seedGiven(); }
  bool seedGiven() const { return prog->seedOverridden || opt.seed.has_value(); }

  /// Copies the globals into the top registers of a production's vars.
  void loadGlobals(double* vars) const {
    const size_t g = prog->globals.size();
    for (size_t k = 0; k < g; ++k) vars[detail::kMaxVars - 1 - k] = globals[k];
  }
  /// The globals a rule's statements assigned (cpfg's notation), for every rule after it.
  void storeGlobals(const double* vars) {
    const size_t g = prog->globals.size();
    for (size_t k = 0; k < g; ++k) globals[k] = vars[detail::kMaxVars - 1 - k];
  }

  detail::Draws* moduleRng() {
    if (cpfgSemantics) {
      draws = {nullptr, &cpfgRandom};
      return &draws;
    }
    if (!rngReady) {
      rng.reseed(deriveSeed(seed, {rngStream, rngItem}));
      rngReady = true;
    }
    draws = {&rng, nullptr};
    return &draws;
  }

  // ---- matching -------------------------------------------------------------------------

  std::vector<int32_t> bracketStack;
  /// Per symbol: skipped by context matching (the main L-system's table, or inside a
  /// sub-L-system's call its own).
  const uint8_t* ignoredTab = nullptr;

  void computeBrackets(const ModuleString& s) {
    size_t n = s.size();
    match.assign(n, -1);
    std::vector<int32_t>& stack = bracketStack;
    stack.clear();
    for (size_t i = 0; i < n; ++i) {
      SymbolId c = s.symbols[i];
      if (c == prog->openBracket) {
        stack.push_back(static_cast<int32_t>(i));
        match[i] = static_cast<int32_t>(n);  // unmatched: its branch runs to the end
      } else if (c == prog->closeBracket && !stack.empty()) {
        match[i] = stack.back();
        match[stack.back()] = static_cast<int32_t>(i);
        stack.pop_back();
      }
    }
  }

  static void bind(const ModuleString& s, size_t i, uint16_t firstVar, uint16_t count, double* vars) {
    const double* p = s.params.data() + s.offsets[i];
    for (uint16_t k = 0; k < count; ++k) vars[firstVar + k] = p[k];
  }

  // The first context neighbour on each side of the current module, computed once per
  // module and shared by every production tried there.
  bool leftCached = false, rightCached = false;
  ptrdiff_t leftNeighbour = -1;
  size_t rightNeighbour = 0;

  /// Position of the first module a symbol pattern item compares with, walking right
  /// from j; n when the walk fails (end of string or a `]`).
  size_t walkRight(const ModuleString& s, size_t j) const {
    const size_t n = s.size();
    bool wrapped = false;
    for (;;) {
      if (j >= n && prog->ring && !wrapped && n > 0) {  // cpfg's ring L-system: on from the start
        j = 0;
        wrapped = true;
      }
      if (j >= n) return n;
      SymbolId c = s.symbols[j];
      if (ignoredTab[c]) ++j;  // brackets only in cpfg's notation (RconDiff skips them first)
      else if (c == prog->openBracket) j = static_cast<size_t>(match[j]) + 1;
      else if (c == prog->closeBracket) return n;
      else return j;
    }
  }

  /// Position of the first module a left pattern item compares with, walking left from j; -1 on failure.
  ptrdiff_t walkLeft(const ModuleString& s, ptrdiff_t j) const {
    bool wrapped = false;
    for (;;) {
      if (j < 0 && prog->ring && !wrapped) {  // cpfg's ring L-system: on from the end
        j = static_cast<ptrdiff_t>(s.size()) - 1;
        wrapped = true;
      }
      if (j < 0) return -1;
      SymbolId c = s.symbols[j];
      if (c == prog->closeBracket) {
        if (match[j] < 0) return -1;
        j = match[j] - 1;
      } else if (c == prog->openBracket || ignoredTab[c]) {
        --j;
      } else {
        return j;
      }
    }
  }

  /// Right context: skips ignored symbols and whole [...] branches; fails at `]`. A `]` in
  /// the pattern skips the rest of the current branch and consumes its `]` (lpfg's rule) in
  /// Sprig's notation; in cpfg's it must be the next module (after ignored symbols and
  /// whole branches), as cpfg's RconDiff compares it, and cpfg's `=` moves to the `]` that
  /// closes the current branch (or the end of the string) without consuming it.
  bool matchRight(const ModuleString& s, size_t i, const std::vector<PatternItem>& pat, double* vars) {
    const size_t n = s.size();
    const bool cpfg = prog->dialect == detail::Dialect::Cpfg;
    size_t j = i + 1;
    if (!pat[0].openBracket && !pat[0].closeBracket && !pat[0].skipBranch) {  // shared first step
      if (!rightCached) {
        rightNeighbour = walkRight(s, i + 1);
        rightCached = true;
      }
      j = rightNeighbour;
      if (j >= n) return false;
    }
    size_t wraps = 0;  // cpfg's ring L-system: at the end of the string, on from the start
    auto wrap = [&] {
      if (j < n || !prog->ring || n == 0 || wraps > pat.size()) return false;
      j = 0;
      ++wraps;
      return true;
    };
    for (const PatternItem& it : pat) {
      if (it.skipBranch || (it.closeBracket && !cpfg)) {  // to the `]` closing the current branch
        while (j < n && s.symbols[j] != prog->closeBracket) {
          if (s.symbols[j] == prog->openBracket) j = static_cast<size_t>(match[j]);
          ++j;
        }
        if (it.skipBranch) continue;
        if (j >= n) return false;
        ++j;
        continue;
      }
      for (;;) {
        if (j >= n && !wrap()) return false;
        SymbolId c = s.symbols[j];
        if (ignoredTab[c]) {
          ++j;
        } else if (c == prog->openBracket) {
          if (it.openBracket) break;
          j = static_cast<size_t>(match[j]) + 1;
        } else if (c == prog->closeBracket) {
          if (it.closeBracket) break;
          return false;
        } else {
          break;
        }
      }
      if (it.openBracket || it.closeBracket) {
        if (s.symbols[j] != (it.openBracket ? prog->openBracket : prog->closeBracket)) return false;
        ++j;
        continue;
      }
      if (s.symbols[j] != it.symbol || s.paramCount(j) != it.paramCount) return false;
      bind(s, j, it.firstVar, it.paramCount, vars);
      ++j;
    }
    return true;
  }

  /// lpfg left context: skips ignored symbols, `[`, and whole branches that end in `]`.
  bool matchLeft(const ModuleString& s, size_t i, const std::vector<PatternItem>& pat, double* vars) {
    ptrdiff_t j = static_cast<ptrdiff_t>(i) - 1;
    for (auto it = pat.rbegin(); it != pat.rend(); ++it) {
      if (it == pat.rbegin()) {
        if (!leftCached) {
          leftNeighbour = walkLeft(s, j);
          leftCached = true;
        }
        j = leftNeighbour;
      } else {
        j = walkLeft(s, j);
      }
      if (j < 0) return false;
      if (s.symbols[j] != it->symbol || s.paramCount(j) != it->paramCount) return false;
      bind(s, static_cast<size_t>(j), it->firstVar, it->paramCount, vars);
      --j;
    }
    return true;
  }

  /// The cut symbol while a derivation step of a grammar in cpfg's notation runs (its `%`
  /// then cuts where the step meets it: pendingCutAt), else -1.
  int32_t cutSym = -1;
  void setCutSym(bool productionStep) {
    cutSym = productionStep && prog->usesCut && prog->dialect == detail::Dialect::Cpfg ? static_cast<int32_t>(prog->cut) : -1;
  }

  std::vector<int32_t> choices;  ///< productions found by context dispatch in the size pass
  std::vector<uint32_t> stochasticIds;  ///< matching stochastic productions of one module
  std::vector<ptrdiff_t> leftStack;

  /// The production context dispatch d selects for parameterless module i, or -1.
  /// ln is the module's left-context neighbour (walkLeft from i - 1), or -1.
  int32_t dispatchAt(const detail::ContextDispatch& d, const ModuleString& s, size_t i, ptrdiff_t ln) const {
    size_t rn = walkRight(s, i + 1);
    uint32_t li = ln >= 0 && s.paramCount(static_cast<size_t>(ln)) == 0 ? d.index[s.symbols[ln]] : 0;
    uint32_t ri = rn < s.size() && s.paramCount(rn) == 0 ? d.index[s.symbols[rn]] : 0;
    return d.table[li * d.width + ri];
  }

  /// Binds p's formal parameters at module i when the predecessor and contexts match.
  bool matches(const Production& p, const ModuleString& s, size_t i, double* vars) {
    if (s.paramCount(i) != p.predParams) return false;
    if (prog->rulesAssignGlobals) loadGlobals(vars);  // as the rules before this one left them
    bind(s, i, p.predFirstVar, p.predParams, vars);
    if (!p.predRest.empty()) {
      // cpfg's predecessor of several modules: the next modules as they stand (PredDiff).
      size_t j = i + 1;
      for (const PatternItem& it : p.predRest) {
        if (j >= s.size() || s.symbols[j] != it.symbol || s.paramCount(j) != it.paramCount) return false;
        if (segIn && &s == &cur && (*segIn)[j] != (*segIn)[i]) return false;  // another successor's module
        bind(s, j, it.firstVar, it.paramCount, vars);
        ++j;
      }
      if (!p.left.empty() && !matchLeft(s, i, p.left, vars)) return false;
      if (!p.right.empty()) {
        // The right context starts after the predecessor's last module; the cached right
        // neighbour (of module i) does not apply there.
        rightCached = false;
        bool ok = matchRight(s, j - 1, p.right, vars);
        rightCached = false;
        if (!ok) return false;
      }
      return true;
    }
    if (p.simpleCtx) {
      if (!p.left.empty()) {
        const PatternItem& it = p.left[0];
        if (!leftCached) {
          leftNeighbour = walkLeft(s, static_cast<ptrdiff_t>(i) - 1);
          leftCached = true;
        }
        if (leftNeighbour < 0 || s.symbols[leftNeighbour] != it.symbol || s.paramCount(leftNeighbour) != it.paramCount) return false;
        bind(s, static_cast<size_t>(leftNeighbour), it.firstVar, it.paramCount, vars);
      }
      if (!p.right.empty()) {
        const PatternItem& it = p.right[0];
        if (!rightCached) {
          rightNeighbour = walkRight(s, i + 1);
          rightCached = true;
        }
        if (rightNeighbour >= s.size() || s.symbols[rightNeighbour] != it.symbol || s.paramCount(rightNeighbour) != it.paramCount) return false;
        bind(s, rightNeighbour, it.firstVar, it.paramCount, vars);
      }
      return true;
    }
    if (!p.left.empty() && !matchLeft(s, i, p.left, vars)) return false;
    if (!p.right.empty() && !matchRight(s, i, p.right, vars)) return false;
    return true;
  }

  /// Runs the statement block r of p (its `before` or `after`) on vars.
  void statements(const Production& p, const detail::CodeRange& r, double* vars, int step) {
    const Instr* code = prog->code.data();
    double v = detail::evalCode(code + r.begin, code + r.end, vars, p.usesRandom ? moduleRng() : nullptr, &prog->strings, &effects,
                                &prog->cpfg, arrays.data());
    if (prog->rulesAssignGlobals) storeGlobals(vars);
    if (std::isnan(v))
      throw InputError(p.loc, "the statements of production '" + p.text + "' loop more than " +
                                  std::to_string(detail::kMaxLoopJumps) + " times at step " + std::to_string(step),
                       p.sourceLine);
  }

  /// p's statements after its condition, when p applies (its successor reads them).
  void afterStatements(const Production& p, double* vars, int step) {
    if (p.after.empty()) return;
    statements(p, p.after, vars, step);
    if (cpfgSemantics) storeLocals(p, vars);
  }

  /// p's local variables into vars: 0 (Sprig's notation), or their values at p's last
  /// use (cpfg's, 0 at first).
  void loadLocals(const Production& p, double* vars) {
    if (!cpfgSemantics) {
      std::fill_n(vars + p.localFirst, p.localCount, 0.0);
      return;
    }
    std::vector<double>& kept = cpfgLocals[&p];
    kept.resize(p.localCount, 0.0);
    std::copy_n(kept.data(), p.localCount, vars + p.localFirst);
  }
  void storeLocals(const Production& p, const double* vars) {
    std::copy_n(vars + p.localFirst, p.localCount, cpfgLocals[&p].data());
  }

  bool condition(const Production& p, double* vars, int step) {
    if (p.hasStatements()) {
      loadLocals(p, vars);
      if (!p.before.empty()) statements(p, p.before, vars, step);
      if (cpfgSemantics) storeLocals(p, vars);
    }
    if (p.condition.empty()) return true;
    const Instr* code = prog->code.data();
    double v = detail::evalCode(code + p.condition.begin, code + p.condition.end, vars, p.usesRandom ? moduleRng() : nullptr,
                                nullptr, nullptr, &prog->cpfg, arrays.data());
    if (std::isnan(v))
      throw InputError(p.loc, "the condition of production '" + p.text + "' is not a number (nan) at step " + std::to_string(step), p.sourceLine);
    return v != 0.0;
  }

  /// cpfg's choice (generate.c, FindProd and SelectProd): without a draw (choiceDraw < 0)
  /// the first applicable production; with one, every applicable production (its
  /// condition evaluated, in order) weighs its probability (1 when it has none) and the
  /// draw picks among them as cpfg does, in float; null when none is picked. The chosen
  /// production's statements are not run again: its variables are those its condition
  /// left.
  const Production* chooseCpfg(const RuleSet& rs, const ModuleString& s, size_t i, double* vars, int step) {
    const std::vector<uint32_t>& cand = rs.bySymbol[s.symbols[i]];
    if (choiceDraw < 0) {
      for (uint32_t id : cand) {
        const Production& p = rs.productions[id];
        if (!matches(p, s, i, vars) || !condition(p, vars, step)) continue;
        afterStatements(p, vars, step);
        return &p;
      }
      return nullptr;
    }
    std::vector<uint32_t>& ids = stochasticIds;
    ids.clear();
    candidateVars.clear();
    float total = 0;
    for (uint32_t id : cand) {
      const Production& p = rs.productions[id];
      if (!matches(p, s, i, vars) || !condition(p, vars, step)) continue;
      ids.push_back(id);
      candidateVars.insert(candidateVars.end(), vars, vars + detail::kMaxVars);
      total += static_cast<float>(p.stochastic ? p.weight : 1.0);
    }
    float scaled = static_cast<float>(static_cast<double>(total) * choiceDraw);
    for (size_t c = 0; c < ids.size(); ++c) {
      const Production& p = rs.productions[ids[c]];
      if ((scaled -= static_cast<float>(p.stochastic ? p.weight : 1.0)) <= 0) {
        std::copy_n(candidateVars.data() + c * detail::kMaxVars, detail::kMaxVars, vars);
        if (prog->rulesAssignGlobals) loadGlobals(vars);  // every candidate's statements ran
        afterStatements(p, vars, step);
        return &p;
      }
    }
    return nullptr;
  }

  /// The production applied to module i of s, with its parameters bound in vars; null to copy.
  const Production* choose(const RuleSet& rs, const ModuleString& s, size_t i, double* vars, int step) {
    if (cpfgSemantics) return chooseCpfg(rs, s, i, vars, step);
    const std::vector<uint32_t>& cand = rs.bySymbol[s.symbols[i]];
    for (size_t k = 0; k < cand.size(); ++k) {
      const Production& p = rs.productions[cand[k]];
      if (!matches(p, s, i, vars) || !condition(p, vars, step)) continue;
      if (!p.stochastic) {
        afterStatements(p, vars, step);
        return &p;
      }
      // Stochastic: choose among every matching weighted production from here on,
      // with probability proportional to its weight.
      std::vector<uint32_t>& ids = stochasticIds;
      ids.clear();
      double total = 0;
      for (size_t q = k; q < cand.size(); ++q) {
        const Production& pq = rs.productions[cand[q]];
        if (!pq.stochastic) continue;
        if (q != k && (!matches(pq, s, i, vars) || !condition(pq, vars, step))) continue;
        ids.push_back(cand[q]);
        total += pq.weight;
      }
      if (total <= 0) return nullptr;
      double r = moduleRng()->uniform() * total;
      size_t pick = ids.size() - 1;
      for (size_t c = 0; c < ids.size(); ++c) {
        double w = rs.productions[ids[c]].weight;
        if (r < w) {
          pick = c;
          break;
        }
        r -= w;
      }
      const Production& chosen = rs.productions[ids[pick]];
      matches(chosen, s, i, vars);  // rebind its parameters
      if (chosen.hasStatements()) {
        // Other candidates' statements used the same registers: run its own again.
        condition(chosen, vars, step);
        afterStatements(chosen, vars, step);
      }
      return &chosen;
    }
    return nullptr;
  }

  // ---- successors -------------------------------------------------------------------------

  [[noreturn]] void nonFinite(const Production& p, const SuccModule& m, int argIndex, double v, int step) const {
    throw InputError(p.loc,
                     "non-finite parameter value (" + numberText(v) + ") in production '" + p.text + "' at step " + std::to_string(step) +
                         " (parameter " + std::to_string(argIndex + 1) + " of '" + prog->symbols.name(m.symbol) + "')",
                     p.sourceLine);
  }

  double evalArg(const Production& p, const SuccModule& m, int k, const double* vars, int step) {
    const Arg& a = p.args[m.firstArg + k];
    double v;
    switch (a.kind) {
      case ArgKind::Const:
        if (!prog->floatParams) return a.c;
        v = a.c;
        break;
      case ArgKind::Var:
        if (!prog->floatParams) return vars[a.var];
        v = vars[a.var];
        break;
      case ArgKind::VarAddConst: v = vars[a.var] + a.c; break;
      case ArgKind::VarMulConst: v = vars[a.var] * a.c; break;
      case ArgKind::VarDivConst: v = vars[a.var] / a.c; break;
      default: {
        const Instr* code = prog->code.data();
        v = detail::evalCode(code + a.code.begin, code + a.code.end, vars, p.usesRandom ? moduleRng() : nullptr, nullptr, nullptr,
                             &prog->cpfg, arrays.data());
      }
    }
    if (prog->floatParams) v = static_cast<double>(static_cast<float>(v));  // cpfg's string holds floats
    if (!std::isfinite(v)) [[unlikely]]
      nonFinite(p, m, k, v, step);
    return v;
  }

  /// Writes p's successor without decomposition.
  [[gnu::always_inline]] inline void emitPlain(Writer& w, const Production& p, const double* vars, int32_t birth, int step) {
    w.reserve(p.successor.size(), p.args.size());
    const Arg* args = p.args.data();
    const bool floats = prog->floatParams;
    for (const SuccModule& m : p.successor) {
      w.begin(m.symbol, birth);
      for (int k = 0; k < m.argCount; ++k) {
        const Arg& a = args[m.firstArg + k];
        switch (floats ? ArgKind::Expr : a.kind) {
          case ArgKind::Const: w.param(a.c); break;
          case ArgKind::Var: w.param(vars[a.var]); break;
          default: w.param(evalArg(p, m, k, vars, step));
        }
      }
      w.end();
    }
  }

  /// Writes p's successor, decomposed by decomp when `decompose` (a derivation step of a
  /// grammar with decomposition rules; cpfg does not decompose the successors of
  /// interpretation rules).
  void emit(Writer& w, const Production& p, const double* vars, int32_t birth, int step, bool decompose,
            const RuleSet* decomp = nullptr) {
    if (!decompose) {
      emitPlain(w, p, vars, birth, step);
      return;
    }
    const RuleSet& rs = decomp ? *decomp : prog->decomposition;
    decompStack.clear();
    decompFrames.clear();
    pushSuccessor(p, vars, step, 0, rs);
    decomposeFrames(w, birth, step, 0, rs);
  }

  // ---- decomposition ----------------------------------------------------------------------
  //
  // cpfg's decomposition (generate.c, ApplyRecursiveProductions), depth first and without
  // recursion: each module of a successor is matched against the decomposition rules (a
  // predecessor of several modules matches the modules after it in the same successor, and
  // replaces them all); a rule's successor is decomposed in turn, one level deeper, up to
  // `maximum depth`; a module no rule matches, or one at maximum depth, is written as it
  // is. The successors being decomposed are kept on an explicit stack (decompStack, one
  // frame per level, each frame's modules after its parent's), so the depth is bounded by
  // kMaxDecompositionNesting and memory, not by the C++ stack.

  /// A successor being decomposed: its modules [begin, end) of decompStack, the next one at pos.
  struct DecompFrame {
    size_t begin, end, pos;
  };
  ModuleString decompStack;
  std::vector<DecompFrame> decompFrames;

  /// Appends p's successor (evaluated with vars) to decompStack as a new frame, whose
  /// modules are at depth `depth` (the decomposition rules applied on the way to them).
  void pushSuccessor(const Production& p, const double* vars, int step, int depth, const RuleSet& rs,
                     const char* what = "decomposition") {
    const size_t begin = decompStack.size();
    if (depth > kMaxDecompositionNesting)
      throw InputError(p.loc, std::string(what) + " nested deeper than " + std::to_string(kMaxDecompositionNesting) +
                                  " levels at step " + std::to_string(step) + " (maximum depth " +
                                  std::to_string(rs.maxDepth) + "): not supported",
                       p.sourceLine);
    for (const SuccModule& m : p.successor) {
      decompStack.symbols.push_back(m.symbol);
      for (int k = 0; k < m.argCount; ++k) decompStack.params.push_back(evalArg(p, m, k, vars, step));
      decompStack.offsets.push_back(static_cast<uint32_t>(decompStack.params.size()));
    }
    decompFrames.push_back({begin, decompStack.size(), begin});
  }

  /// Done with the top frame's successor: drops its modules (the top frame's are the last)
  /// and the frame.
  void popDecompFrame() {
    const size_t begin = decompFrames.back().begin;
    decompStack.symbols.resize(begin);
    decompStack.offsets.resize(begin + 1);
    decompStack.params.resize(decompStack.offsets[begin]);
    decompFrames.pop_back();
  }

  /// Decomposes the frames on the stack (the bottom one at depth base) into w until the
  /// stack is empty. Frame k of decompFrames is at depth base + k.
  void decomposeFrames(Writer& w, int32_t birth, int step, int base, const RuleSet& rs) {
    double vars[detail::kMaxVars];
    loadGlobals(vars);
    while (!decompFrames.empty()) {
      DecompFrame& f = decompFrames.back();
      if (f.pos >= f.end) {
        popDecompFrame();
        continue;
      }
      const size_t i = f.pos;
      const int depth = base + static_cast<int>(decompFrames.size()) - 1;
      const Production* p = depth < rs.maxDepth && !rs.bySymbol[decompStack.symbols[i]].empty()
                                ? choose(rs, decompStack, i, vars, step)
                                : nullptr;
      if (!p) {
        const uint32_t count = decompStack.paramCount(i);
        w.reserve(1, count);
        w.copy(decompStack.symbols[i], decompStack.params.data() + decompStack.offsets[i], count, birth);
        ++f.pos;
        continue;
      }
      f.pos += 1 + p->predRest.size();  // f is not used past this point: the push may move it
      pushSuccessor(*p, vars, step, depth + 1, rs);
    }
  }

  /// Writes module i of s (the string being rewritten, which no production changed at i)
  /// decomposed: a decomposition rule's predecessor of several modules matches the modules
  /// of s after i, as cpfg's does. Returns the number of modules after i it replaced.
  size_t emitDecomposed(Writer& w, const ModuleString& s, size_t i, int32_t birth, int step, const RuleSet& rs) {
    double vars[detail::kMaxVars];
    loadGlobals(vars);
    const Production* p = rs.maxDepth > 0 && !rs.bySymbol[s.symbols[i]].empty() ? choose(rs, s, i, vars, step) : nullptr;
    if (!p) {
      const uint32_t count = s.paramCount(i);
      w.reserve(1, count);
      w.copy(s.symbols[i], s.params.data() + s.offsets[i], count, birth);
      return 0;
    }
    decompStack.clear();
    decompFrames.clear();
    pushSuccessor(*p, vars, step, 1, rs);
    decomposeFrames(w, birth, step, 1, rs);
    return p->predRest.size();
  }

  // ---- steps ----------------------------------------------------------------------------

  /// Size pass over cur before rewriting it with rs: the exact output size when every
  /// module's production is known without evaluating anything (simple productions, copies,
  /// context dispatch), else a modest start that grows on demand. Appends to choices the
  /// production context dispatch selects for each dispatched module, in order. Throws the
  /// module-limit InputError when the exact size is over the limit, before any allocation.
  /// Returns {modules, parameters} to reserve.
  [[gnu::always_inline]] inline std::pair<size_t, size_t> sizePass(const RuleSet& rs, int step) {
    const ModuleString& in = cur;
    const size_t n = in.size();
    const SymbolId* syms = in.symbols.data();
    const uint32_t* offs = in.offsets.data();
    const detail::SymbolRules* rules = rs.rules.data();
    size_t boundM = 0, boundP = 0;
    bool exact = true;
    // The left-context neighbour of each module, kept incrementally: the last module
    // neither ignored nor a bracket on the path from the root, restored after each
    // branch (the same answer as walkLeft, in O(1) per module).
    ptrdiff_t lastSeen = -1;
    leftStack.clear();
    const bool trackLeft = !rs.dispatches.empty();
    const uint8_t* ignored = ignoredTab;
    size_t cutUntil = 0;  // modules before it are in a cut branch the step skips
    for (size_t i = 0; i < n; ++i) {
      const detail::SymbolRules& r = rules[syms[i]];
      uint32_t count = offs[i + 1] - offs[i];
      if (trackLeft && i > 0) {
        SymbolId c = syms[i - 1];
        if (c == prog->openBracket) {
          leftStack.push_back(lastSeen);
        } else if (c == prog->closeBracket) {
          lastSeen = leftStack.empty() ? -1 : leftStack.back();
          if (!leftStack.empty()) leftStack.pop_back();
        } else if (!ignored[c]) {
          lastSeen = static_cast<ptrdiff_t>(i - 1);
        }
      }
      if (i < cutUntil) continue;
      if (r.count == 0 || (r.simple && count != r.simple->predParams)) {
        if (r.count == 0 && pendingCutAt(in, i)) cutUntil = cutEnd(in, i, n);
        boundM += 1;
        boundP += count;
      } else if (r.simple) {
        boundM += r.simple->successor.size();
        boundP += r.simple->args.size();
      } else if (r.dispatch >= 0 && count == 0) {
        int32_t idx = dispatchAt(rs.dispatches[r.dispatch], in, i, lastSeen);
        choices.push_back(idx);
        if (idx < 0 && pendingCutAt(in, i)) cutUntil = cutEnd(in, i, n);
        boundM += idx < 0 ? 1 : rs.productions[static_cast<size_t>(idx)].successor.size();
        boundP += idx < 0 ? 0 : rs.productions[static_cast<size_t>(idx)].args.size();
      } else {
        boundM += r.maxModules;
        boundP += std::max(r.maxParams, count);
        exact = false;
      }
    }
    if (boundM > opt.maxModules && exact) Writer::overLimit(opt.maxModules, limitAt, step);
    if (exact) return {boundM, boundP};
    // A loose bound (conditions, contexts, choices): start modestly, grow on demand.
    return {std::min({boundM, opt.maxModules, 2 * n + 16}), std::min(boundP, 2 * in.params.size() + 16)};
  }

  /// Copies modules i, i+1, ... of cur that no production of rs touches (rules[s].count
  /// is 0) into w; returns the index of the last one copied.
  [[gnu::always_inline]] inline size_t copyUntouched(Writer& w, const detail::SymbolRules* rules, size_t i) {
    const ModuleString& in = cur;
    const size_t n = in.size();
    const SymbolId* syms = in.symbols.data();
    const uint32_t* offs = in.offsets.data();
    const bool births = opt.trackBirthSteps;
    size_t j = i + 1;
    while (j < n && rules[syms[j]].count == 0 && static_cast<int32_t>(syms[j]) != cutSym) ++j;
    if (j - i >= 8) {  // a long run: bulk copies pay off
      w.copyRun(syms + i, offs + i, in.params.data(), j - i, births ? in.birthSteps.data() + i : nullptr);
    } else {
      for (size_t k = i; k < j; ++k) {
        uint32_t count = offs[k + 1] - offs[k];
        w.reserve(1, count);
        w.copy(syms[k], in.params.data() + offs[k], count, births ? in.birthSteps[k] : 0);
      }
    }
    return j - 1;
  }

  /// The rules of one L-system of a grammar with cpfg's sub-L-systems: the main one's or a
  /// sub-L-system's (generate.c and interpret.c take each from the L-system on top of their
  /// stack: LSYSDATA's productions, Decomposition, Homomorphism and ignore table).
  struct LsystemRules {
    const RuleSet* productions = nullptr;
    const RuleSet* decomposition = nullptr;
    const RuleSet* interpretation = nullptr;
    const uint8_t* ignored = nullptr;
  };
  /// [0] the main L-system, then the sub-L-systems in file order (filled on first use).
  std::vector<LsystemRules> lsystems;

  void makeLsystems() {
    if (!lsystems.empty()) return;
    lsystems.push_back({&prog->productions, &prog->decomposition, &prog->interpretation, prog->ignored.data()});
    for (const detail::SubLsystem& sub : prog->subLsystems)
      lsystems.push_back({&sub.productions, &sub.decomposition, &sub.interpretation, sub.ignored.data()});
  }

  /// The index in lsystems of the L-system `?(id, ...)` calls at step (0, the main one, for
  /// its own number); an unknown id is an InputError.
  size_t calledLsystem(double id, int step) const {
    for (size_t k = 0; k < prog->subLsystems.size(); ++k)
      if (prog->subLsystems[k].id == id) return k + 1;
    if (prog->mainLsystemId && *prog->mainLsystemId == id) return 0;
    std::string known;
    if (prog->mainLsystemId) known = numberText(*prog->mainLsystemId);
    for (const detail::SubLsystem& sub : prog->subLsystems) known += (known.empty() ? "" : ", ") + numberText(sub.id);
    throw InputError(prog->subLsystems.front().loc, "'?(" + numberText(id) + ", ...)' at step " + std::to_string(step) +
                                                        " calls a sub-L-system the file does not define (its L-systems: " + known + ")",
                     prog->subLsystems.front().sourceLine);
  }

  /// Switches the L-system stack at module i of s: `?(n, s)` pushes L-system n, `$` pops
  /// (an unmatched `$` leaves the main one, as cpfg does after its warning).
  void switchLsystem(std::vector<size_t>& stack, const ModuleString& s, size_t i, int step) const {
    const SymbolId sym = s.symbols[i];
    if (prog->subCall && sym == *prog->subCall && s.paramCount(i) >= 1) stack.push_back(calledLsystem(s.params[s.offsets[i]], step));
    else if (sym == prog->subEnd && stack.size() > 1) stack.pop_back();
  }

  /// One derivation step of a grammar with cpfg's sub-L-systems (generate.c, Derive,
  /// ApplyProd and CheckPred): a stack of L-systems starts with the main one; each module is
  /// rewritten by the productions of the L-system on top (contexts matched with its ignore
  /// table), and what they write, or the module itself when none applies, is decomposed by
  /// that L-system's decomposition rules up to its maximum depth; then the modules the
  /// production matched switch L-systems: `?(n, s)` pushes sub-L-system n, `$` pops.
  void rewriteWithSubLsystems(int step, uint64_t stream) {
    makeLsystems();
    const ModuleString& in = cur;
    const size_t n = in.size();
    const bool births = opt.trackBirthSteps;
    computeBrackets(in);
    Writer w(next, births, opt.maxModules, limitAt, step, std::min(opt.maxModules, 2 * n + 16), 2 * in.params.size() + 16);
    double vars[detail::kMaxVars];
    loadGlobals(vars);
    rngStream = stream;
    const bool cpfgChoice = cpfgSemantics && stochasticCpfg();
    std::vector<size_t> stack{0};
    setCutSym(true);
    for (size_t i = 0; i < n; ++i) {
      const LsystemRules& ls = lsystems[stack.back()];
      ignoredTab = ls.ignored;
      const SymbolId sym = in.symbols[i];
      const int32_t birth = births ? in.birthSteps[i] : 0;
      rngReady = false;
      rngItem = i;
      leftCached = rightCached = false;
      choiceDraw = cpfgChoice ? cpfgRandom.choice.next() : -1;
      const Production* p = ls.productions->rules[sym].count == 0 ? nullptr : choose(*ls.productions, in, i, vars, step);
      choiceDraw = -1;
      const bool decompose = !ls.decomposition->empty();
      if (!p && pendingCutAt(in, i) && !(decompose && !ls.decomposition->bySymbol[sym].empty())) {
        i = cutEnd(in, i, n) - 1;  // cpfg's cut, made when the step reaches it (up to the call's `$`)
        continue;
      }
      size_t last = i;
      if (!p && cpfgChoice) copiedCharacterDraws(sym, decompose ? ls.decomposition : nullptr);
      if (p) {
        emit(w, *p, vars, step, step, decompose, ls.decomposition);
        last = i + p->predRest.size();
      } else if (decompose) {
        last = i + emitDecomposed(w, in, i, birth, step, *ls.decomposition);
      } else {
        const uint32_t count = in.paramCount(i);
        w.reserve(1, count);
        w.copy(sym, in.params.data() + in.offsets[i], count, birth);
      }
      for (size_t k = i; k <= last; ++k) switchLsystem(stack, in, k, step);
      i = last;
    }
    ignoredTab = prog->ignored.data();
    w.finish();
    written += w.modules();
    std::swap(cur, next);
    cutAfterStep();
  }

  /// cpfg's homomorphism in a grammar with sub-L-systems (interpret.c, TurtleDrawNsteps,
  /// InterpretHomomorphism and UpdateCurrentLsystem), writing s as the turtle reads it into
  /// w: depth first, each module is rewritten by the interpretation rules of the L-system
  /// current when the turtle reaches it, up to that L-system's maximum depth; a module no
  /// rule rewrites is drawn, and a drawn `?(n, s)` or `$` switches L-systems for everything
  /// after it, inside a successor too. A predecessor of several modules matches the modules
  /// after it in s at the first level, in one successor deeper.
  void homomorphismWithSubLsystems(const ModuleString& s, Writer& w, int step) {
    makeLsystems();
    const bool births = s.hasBirthSteps();
    double vars[detail::kMaxVars];
    loadGlobals(vars);
    std::vector<size_t> stack{0};
    auto draw = [&](const ModuleString& from, size_t i, int32_t birth) {
      const uint32_t count = from.paramCount(i);
      w.reserve(1, count);
      w.copy(from.symbols[i], from.params.data() + from.offsets[i], count, birth);
      switchLsystem(stack, from, i, step);
    };
    uint64_t item = 0;
    // The rule of the current L-system for module i of from at depth, or null.
    auto rule = [&](const ModuleString& from, size_t i, int depth) -> const Production* {
      const RuleSet& rs = *lsystems[stack.back()].interpretation;
      if (rs.empty() || depth >= rs.maxDepth || rs.bySymbol[from.symbols[i]].empty()) return nullptr;
      rngReady = false;
      rngStream = kInterpretStream - static_cast<uint64_t>(depth);
      rngItem = item++;
      leftCached = rightCached = false;
      return choose(rs, from, i, vars, step);
    };
    for (size_t i = 0; i < s.size(); ++i) {
      const int32_t birth = births ? s.birthSteps[i] : 0;
      const Production* p = rule(s, i, 0);
      if (!p) {
        draw(s, i, birth);
        continue;
      }
      i += p->predRest.size();
      decompStack.clear();
      decompFrames.clear();
      pushSuccessor(*p, vars, step, 1, *lsystems[stack.back()].interpretation, "interpretation");
      while (!decompFrames.empty()) {
        DecompFrame& f = decompFrames.back();
        if (f.pos >= f.end) {
          popDecompFrame();
          continue;
        }
        const size_t k = f.pos;
        const int depth = static_cast<int>(decompFrames.size());
        const Production* q = rule(decompStack, k, depth);
        if (!q) {
          draw(decompStack, k, birth);
          ++f.pos;
          continue;
        }
        f.pos += 1 + q->predRest.size();  // f is not used past this point: the push may move it
        pushSuccessor(*q, vars, step, depth + 1, *lsystems[stack.back()].interpretation, "interpretation");
      }
    }
  }

  /// Rewrites cur into next with rules rs (one derivation step when rs is the main block).
  void rewrite(const RuleSet& rs, int step, uint64_t stream, bool productionStep) {
    if (productionStep && !prog->subLsystems.empty() && &rs == &prog->productions) {
      rewriteWithSubLsystems(step, stream);
      return;
    }
    const ModuleString& in = cur;
    const size_t n = in.size();
    const bool births = opt.trackBirthSteps;
    const bool decompose = !prog->decomposition.empty() && productionStep;
    setCutSym(productionStep);
    // Each module through the general path below: decomposition, or successors tracked.
    // (A production for cpfg's pending `%` leaves the size pass unable to tell which
    // modules the step skips.)
    // cpfg's stochastic L-system: one drand48 draw for every module a step visits.
    const bool cpfgChoice = productionStep && cpfgSemantics && stochasticCpfg();
    // (Rules that assign globals run one module after another, never in the size pass.)
    const bool general = decompose || segIn || cpfgChoice || prog->rulesAssignGlobals || prog->ring ||
                         (cutSym >= 0 && rs.rules[static_cast<size_t>(cutSym)].count > 0);
    if (segOut) segOut->clear();
    uint32_t segments = 0;
    const SymbolId* syms = in.symbols.data();
    const uint32_t* offs = in.offsets.data();
    const double* pars = in.params.data();
    const detail::SymbolRules* rules = rs.rules.data();
    // The buffers are allocated once from the size pass, and a limit overrun is caught
    // before allocating.
    // Dispatch tables walk to neighbours over brackets too: a symbol with several
    // context-free productions (the first always wins) has one (fuzz regression
    // derive/crash-0836...).
    if (rs.anyContext || !rs.dispatches.empty()) computeBrackets(in);
    choices.clear();
    auto [reserveModules, reserveParams] = general ? std::pair<size_t, size_t>{0, 0} : sizePass(rs, step);
    Writer w(next, births, opt.maxModules, limitAt, step, reserveModules, reserveParams);
    double vars[detail::kMaxVars];
    loadGlobals(vars);
    rngStream = stream;
    size_t nextChoice = 0;
    for (size_t i = 0; i < n; ++i) {
      SymbolId sym = syms[i];
      int32_t birth = births ? in.birthSteps[i] : 0;
      const detail::SymbolRules& r = rules[sym];
      double draw = cpfgChoice ? cpfgRandom.choice.next() : -1;  // drawn before any cut, as cpfg does
      // A command a rule for its letter rewrites: cpfg visits '@' first, the letter last.
      const bool split = cpfgChoice && sym < prog->splitCommand.size() && prog->splitCommand[sym];
      for (size_t k = 1; split && k < prog->symbols.name(sym).size(); ++k) draw = cpfgRandom.choice.next();
      if (r.count == 0 && pendingCutAt(in, i) && !(decompose && !prog->decomposition.bySymbol[sym].empty())) {
        i = cutEnd(in, i, n) - 1;  // cpfg's cut, made when the step reaches it
        continue;
      }
      if (r.count == 0 && !general) {
        i = copyUntouched(w, rules, i);
        continue;
      }
      if (r.simple && !general) {
        const Production& p = *r.simple;
        uint32_t count = offs[i + 1] - offs[i];
        if (count == p.predParams) {
          const double* q = pars + offs[i];
          for (uint32_t k = 0; k < count; ++k) vars[p.predFirstVar + k] = q[k];
          if (p.usesRandom) {
            rngReady = false;
            rngItem = i;
          }
          emitPlain(w, p, vars, productionStep ? step : birth, step);
          continue;
        }
      }
      if (r.dispatch >= 0 && !general && offs[i + 1] == offs[i]) {
        int32_t idx = choices[nextChoice++];
        if (idx < 0 && pendingCutAt(in, i)) {
          i = cutEnd(in, i, n) - 1;
        } else if (idx < 0) {
          w.reserve(1, 0);
          w.copy(sym, nullptr, 0, birth);
        } else {
          emitPlain(w, rs.productions[static_cast<size_t>(idx)], vars, productionStep ? step : birth, step);
        }
        continue;
      }
      rngReady = false;
      rngItem = i;
      leftCached = rightCached = false;
      const size_t before = w.modules();
      choiceDraw = draw;
      const Production* p = r.count == 0 || (segIn && (*segIn)[i] == kFrozen) ? nullptr : choose(rs, in, i, vars, step);
      choiceDraw = -1;  // decomposition chooses the first applicable rule
      if (!p && pendingCutAt(in, i) && !(decompose && !prog->decomposition.bySymbol[sym].empty())) {
        i = cutEnd(in, i, n) - 1;
        continue;
      }
      if (!p) {
        if (cpfgChoice && !split) copiedCharacterDraws(sym, decompose ? &prog->decomposition : nullptr);
        if (decompose && productionStep) {
          i += emitDecomposed(w, in, i, birth, step, prog->decomposition);
        } else {
          uint32_t count = offs[i + 1] - offs[i];
          w.reserve(1, count);
          w.copy(sym, pars + offs[i], count, birth);
        }
        if (segOut) segOut->insert(segOut->end(), w.modules() - before, kFrozen);
        continue;
      }
      emit(w, *p, vars, productionStep ? step : birth, step, decompose);
      i += p->predRest.size();  // a predecessor of several modules replaces them all
      if (segOut) segOut->insert(segOut->end(), w.modules() - before, segments++);
    }
    w.finish();
    written += w.modules();
    std::swap(cur, next);
    cutAfterStep();
  }

  /// The end of the cut `%` at module i of s makes, looking no further than end: the index
  /// of the `]` closing its branch, of the `$` ending the sub-L-system call it is in (cpfg's
  /// SkipCutPart), or end.
  size_t cutEnd(const ModuleString& s, size_t i, size_t end) const {
    int depth = 0, subDepth = 0;
    const bool subs = !prog->subLsystems.empty();
    size_t j = i + 1;
    for (; j < end; ++j) {
      SymbolId c = s.symbols[j];
      if (c == prog->openBracket) ++depth;
      else if (c == prog->closeBracket && depth-- == 0) break;
      else if (subs && prog->subCall && c == *prog->subCall && s.paramCount(j) >= 1) ++subDepth;
      else if (subs && c == prog->subEnd && subDepth-- == 0) break;
    }
    return j;
  }

  /// True when module i of s is a `%` that cuts when a cpfg step reaches it (cutSym: the
  /// cut symbol in cpfg's notation during a derivation step, else none).
  bool pendingCutAt(const ModuleString& s, size_t i) const {
    return static_cast<int32_t>(s.symbols[i]) == cutSym && s.paramCount(i) == 0;
  }

  /// Removes the rest of every `%`'s branch (up to, not including, the closing `]`). The
  /// `%` stays, so that the turtle marks the internode it ends as cut (a saw face,
  /// docs/TREES.md "Pruning"); once its branch is gone, later cuts leave it as it is.
  void applyCuts(ModuleString& s) const {
    const size_t n = s.size();
    const bool births = s.birthSteps.size() == n && n > 0;
    size_t j = 0, pj = 0;
    size_t i = 0;
    bool any = false;
    while (i < n) {
      const size_t next = s.symbols[i] == prog->cut ? cutEnd(s, i, n) : i + 1;
      any = any || next > i + 1;
      uint32_t b = s.offsets[i], e = s.offsets[i + 1];
      s.symbols[j] = s.symbols[i];
      if (births) s.birthSteps[j] = s.birthSteps[i];
      for (uint32_t k = b; k < e; ++k) s.params[pj++] = s.params[k];
      s.offsets[j + 1] = static_cast<uint32_t>(pj);
      ++j;
      i = next;
    }
    if (!any) return;
    s.symbols.resize(j);
    s.offsets.resize(j + 1);
    s.params.resize(pj);
    if (births) s.birthSteps.resize(j);
  }

  /// After a step: Sprig's notation removes the cut branches now (keeping each `%`); cpfg's keeps each `%` and
  /// the rest of its branch in the string until the next step skips them (generate.c,
  /// ApplyProd: SkipCutPart), so its final string holds them and the turtle skips them.
  void cutAfterStep() {
    if (prog->usesCut && prog->dialect != detail::Dialect::Cpfg) applyCuts(cur);
  }

  /// cpfg's axiom parameters that read global variables, evaluated once the `Start:` block
  /// has run (control.c, Rewind: EvaluateStartStatements, then CreateParameterString);
  /// their random draws come from cpfg's stream, after the block's.
  void evaluateDeferredAxiom() {
    if (prog->axiomDeferred.empty()) return;
    double vars[detail::kMaxVars] = {};
    loadGlobals(vars);
    detail::Draws d{nullptr, &cpfgRandom};
    const Instr* code = prog->code.data();
    for (const auto& [index, r] : prog->axiomDeferred) {
      const double v =
          detail::evalCode(code + r.begin, code + r.end, vars, &d, nullptr, nullptr, &prog->cpfg, arrays.data());
      if (!std::isfinite(v))
        throw InputError(prog->axiomLoc, "non-finite parameter value (" + numberText(v) + ") in the axiom, from the values "
                                         "the 'Start:' block gave its global variables", prog->axiomLine);
      cur.params[index] = static_cast<double>(static_cast<float>(v));
    }
  }

  void start() {
    globals.assign(detail::kMaxVars, 0.0);
    arrays = prog->cpfg.arrayInit;
    effects = {};
    seed = baseSeed;
    cpfgSemantics = prog->dialect == detail::Dialect::Cpfg;
    cpfgLocals.clear();
    // cpfg -g's drand48 starts unseeded; a seed given to Sprig seeds it as cpfg's window does.
    cpfgRandom = detail::CpfgRandom::forSeed(seedGiven() ? seed : 0);
    streamBase = 0;
    steps = baseSteps;
    // cpfg closes the files of a derivation before it starts again (FreeFileDefSpace).
    files->closeAll();
    files->setFolder(std::filesystem::path(prog->fileName).parent_path().string());
    effects.files = files.get();
    runBlock(prog->startBlock, 0, 0);
    cur = prog->axiom;
    evaluateDeferredAxiom();
    if (cur.size() > opt.maxModules) Writer::overLimit(opt.maxModules, limitAt, 0);
    if (opt.trackBirthSteps) cur.birthSteps.assign(cur.size(), 0);
    // cpfg's notation: cpfg neither decomposes nor cuts the axiom before the first step
    // (control.c, Rewind: CreateParameterString); step 1 decomposes the modules no
    // production rewrites, as every step does (generate.c, ApplyProd).
    if (prog->dialect != detail::Dialect::Cpfg && !prog->decomposition.empty()) {
      RuleSet none;
      none.bySymbol.assign(prog->symbols.size(), {});
      none.finalize();
      rewrite(none, 0, 0, true);
    } else {
      cutAfterStep();
    }
    written = 0;
    queriesAfter(0);
  }
};

Deriver::Deriver(const Grammar& grammar, DeriveOptions options) : impl_(std::make_unique<Impl>()) {
  impl_->grammar = grammar;
  impl_->prog = &grammar.program();
  impl_->ignoredTab = impl_->prog->ignored.data();
  impl_->steps = options.steps.value_or(grammar.derivationLength());
  impl_->seed = impl_->baseSeed = options.seed.value_or(grammar.seed());
  impl_->baseSteps = impl_->steps;
  impl_->opt = std::move(options);
  impl_->locateLimit();
  impl_->start();
}

Deriver::~Deriver() = default;
Deriver::Deriver(Deriver&&) noexcept = default;
Deriver& Deriver::operator=(Deriver&&) noexcept = default;

void Deriver::restart() {
  if (impl_->opt.environment) impl_->opt.environment->restart();  // cpfg restarts it on rewind
  impl_->done = 0;
  impl_->start();
}

const ModuleString& Deriver::step() {
  Impl& m = *impl_;
  int step = m.done + 1;
  const bool envBefore = m.environmentActive() && !m.opt.environmentAfterEachStep && !m.environmentDone;
  if (m.queriesPending || envBefore) {
    m.queriesPending = false;
    m.fillQueries(envBefore);  // cpfg interprets the string when the next step starts
  }
  m.runBlock(m.prog->startEachBlock, step, step - 1);
  m.rewrite(m.prog->productions, step, static_cast<uint64_t>(step - m.streamBase), true);
  m.runBlock(m.prog->endEachBlock, step, step);
  // cpfg's stop(x): the derivation ends after this step (control.c, GenerateNSteps).
  if (m.effects.stop) m.steps = step;
  if (step == m.steps) m.runBlock(m.prog->endBlock, step, step);
  m.done = step;
  m.queriesAfter(step);
  if (m.opt.onStep) m.opt.onStep(step, m.cur.size());
  return m.cur;
}

const ModuleString& Deriver::derive() {
  while (impl_->done < impl_->steps) step();
  return impl_->cur;
}

const ModuleString& Deriver::current() const { return impl_->cur; }
int Deriver::stepsDone() const { return impl_->done; }
int Deriver::steps() const { return impl_->steps; }
uint64_t Deriver::seed() const { return impl_->seed; }
const SymbolTable& Deriver::symbols() const { return impl_->prog->symbols; }
uint64_t Deriver::modulesWritten() const { return impl_->written; }
bool Deriver::hasInterpretation() const { return impl_->prog->anyInterpretation(); }

ModuleString Deriver::interpret(const ModuleString& s) const {
  if (!impl_->prog->anyInterpretation()) return s;
  // A private Impl shares the program and seed so interpret() stays const on this Deriver.
  return impl_->interpreted(s, impl_->done);
}

ModuleString derive(const Grammar& grammar, const DeriveOptions& options) {
  Deriver d(grammar, options);
  return d.derive();
}

std::string formatModuleString(const ModuleString& s, const SymbolTable& symbols, const FormatOptions& options) {
  std::string out;
  size_t lineStart = 0;
  char buf[64];
  for (size_t i = 0; i < s.size(); ++i) {
    const std::string& name = symbols.name(s.symbols[i]);
    if (options.wrapColumn && out.size() - lineStart >= options.wrapColumn) {
      out += '\n';
      lineStart = out.size();
    } else if (i > 0 && s.paramCount(i - 1) == 0) {
      const std::string& prev = symbols.name(s.symbols[i - 1]);
      bool prevWord = prev.size() > 1 && std::isalnum(static_cast<unsigned char>(prev.back()));
      if (prevWord && std::isalnum(static_cast<unsigned char>(name[0]))) out += ' ';
    }
    out += name;
    uint32_t count = s.paramCount(i);
    if (count) {
      out += '(';
      auto p = s.paramsOf(i);
      for (uint32_t k = 0; k < count; ++k) {
        if (k) out += ',';
        auto r = options.floatParams ? std::to_chars(buf, buf + sizeof buf, static_cast<float>(p[k]))
                                     : std::to_chars(buf, buf + sizeof buf, p[k]);
        out.append(buf, r.ptr);
      }
      out += ')';
    }
  }
  return out;
}

size_t countSymbol(const ModuleString& s, const SymbolTable& symbols, std::string_view name) {
  int id = symbols.find(name);
  if (id < 0) return 0;
  return static_cast<size_t>(std::count(s.symbols.begin(), s.symbols.end(), static_cast<SymbolId>(id)));
}

}  // namespace sprig::lsystem
