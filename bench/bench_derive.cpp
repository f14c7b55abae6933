/// Derivation throughput (modules written per second, one core).
///
/// Derives ABOP figure 1.24a (n = 5), figure 2.6 (n = 14) and the context-sensitive
/// figure 1.31a (n = 30) with the grammar interpreter (lsystem::Deriver), and in the same
/// run a hand-written C++ rewrite of the 2.6 grammar (a switch over its three productions
/// writing the same ModuleString layout) as the ceiling. Prints modules/s for each and the
/// ratios the targets name (interpreter / ceiling on 2.6, context-sensitive /
/// context-free). Each figure is the best of several timed runs of at least 0.2 s.
///
///   build/bench/bench_derive [SOURCE_DIR]
///
/// SOURCE_DIR (default: the current folder) holds tests/assets/lsystem/.

#include <algorithm>
#include <memory>
#include <cstdio>
#include <string>

#include "bench/bench_clock.h"
#include "lsystem/derive.h"
#include "lsystem/grammar.h"

using namespace sprig;
using namespace sprig::lsystem;
using sprig::bench::threadCpuSeconds;

namespace {

/// Best modules/s over runs of fn (which returns modules written), each run >= 0.2 s of CPU time.
template <class Fn>
double rate(Fn&& fn, int rounds = 5) {
  double best = 0;
  for (int r = 0; r < rounds; ++r) {
    uint64_t modules = 0;
    double t0 = threadCpuSeconds();
    double secs = 0;
    do {
      modules += fn();
      secs = threadCpuSeconds() - t0;
    } while (secs < 0.2);
    best = std::max(best, static_cast<double>(modules) / secs);
  }
  return best;
}

/// Hand-written ABOP 2.6: the same three productions, the same string layout, a switch on
/// the symbol id and raw pointer writes into buffers sized exactly from a size pass.
struct Handwritten26 {
  static constexpr double r1 = 0.9, r2 = 0.6, a0 = 45, a2 = 45, d = 137.5, wr = 0.707;
  SymbolId A, B, C, F, bang, open, close, amp, slash, minus, plus, dollar;

  explicit Handwritten26(const SymbolTable& t) {
    auto id = [&](const char* n) { return static_cast<SymbolId>(t.find(n)); };
    A = id("A"), B = id("B"), C = id("C"), F = id("F"), bang = id("!"), open = id("["), close = id("]");
    amp = id("&"), slash = id("/"), minus = id("-"), plus = id("+"), dollar = id("$");
  }

  /// Derives n steps from A(1,10); returns the modules written.
  uint64_t run(int n, ModuleString& cur, ModuleString& next) const {
    cur.clear();
    double axiom[2] = {1, 10};
    cur.push(A, axiom);
    uint64_t written = 0;
    for (int step = 0; step < n; ++step) {
      size_t m = cur.size(), outM = 0, outP = 0;
      for (size_t i = 0; i < m; ++i) {
        SymbolId s = cur.symbols[i];
        if (s == A || s == B || s == C) {
          outM += 8;
          outP += s == A ? 8 : 7;
        } else {
          outM += 1;
          outP += cur.paramCount(i);
        }
      }
      next.symbols.resize(outM);
      next.offsets.resize(outM + 1);
      next.params.resize(outP);
      SymbolId* sym = next.symbols.data();
      uint32_t* off = next.offsets.data();
      double* par = next.params.data();
      const double* in = cur.params.data();
      size_t o = 0;
      uint32_t p = 0;
      off[0] = 0;
      auto mod0 = [&](SymbolId s) { sym[o] = s; off[++o] = p; };
      auto mod1 = [&](SymbolId s, double a) { sym[o] = s; par[p++] = a; off[++o] = p; };
      auto mod2 = [&](SymbolId s, double a, double b) { sym[o] = s; par[p++] = a; par[p++] = b; off[++o] = p; };
      for (size_t i = 0; i < m; ++i) {
        SymbolId s = cur.symbols[i];
        const double* q = in + cur.offsets[i];
        if (s == A) {  // !(w)F(l)[&(a0)B(l*r2,w*wr)]/(d)A(l*r1,w*wr)
          double l = q[0], w = q[1];
          mod1(bang, w), mod1(F, l), mod0(open), mod1(amp, a0), mod2(B, l * r2, w * wr), mod0(close), mod1(slash, d),
              mod2(A, l * r1, w * wr);
        } else if (s == B || s == C) {  // !(w)F(l)[-(a2)$C(l*r2,w*wr)]C(l*r1,w*wr), B and C mirrored
          double l = q[0], w = q[1];
          SymbolId turn = s == B ? minus : plus, other = s == B ? C : B;
          mod1(bang, w), mod1(F, l), mod0(open), mod1(turn, a2), mod0(dollar), mod2(other, l * r2, w * wr), mod0(close),
              mod2(other, l * r1, w * wr);
        } else {
          uint32_t c = cur.paramCount(i);
          sym[o] = s;
          for (uint32_t k = 0; k < c; ++k) par[p++] = q[k];
          off[++o] = p;
        }
      }
      written += outM;
      std::swap(cur, next);
    }
    return written;
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::string root = argc > 1 ? argv[1] : ".";
  auto load = [&](const char* name) { return loadGrammar(root + "/tests/assets/lsystem/" + name); };
  try {
    Grammar g124a = load("abop_1_24a.lsys");
    Grammar g26 = load("abop_2_6.lsys");
    Grammar g131 = load("abop_1_31a.lsys");

    auto interp = [](const Grammar& g, int n) {
      DeriveOptions opt;
      opt.steps = n;
      return [&g, opt]() {
        Deriver d(g, opt);
        d.derive();
        return d.modulesWritten();
      };
    };
    size_t final124 = derive(g124a, {}).size();
    DeriveOptions o26;
    o26.steps = 14;
    size_t final26 = derive(g26, o26).size();
    DeriveOptions o131;
    o131.steps = 30;
    size_t final131 = derive(g131, o131).size();

    // Warm: one Deriver restarted per run, so its buffers are reused (as the hand-written
    // rewrite reuses its two strings); fresh: a new Deriver (new memory) per run.
    auto warm = [](const Grammar& g, int n) {
      DeriveOptions opt;
      opt.steps = n;
      auto d = std::make_shared<Deriver>(g, opt);
      return [d]() {
        d->restart();
        d->derive();
        return d->modulesWritten();
      };
    };
    double r124 = rate(warm(g124a, 5));
    double r26 = rate(warm(g26, 14));
    double r131 = rate(warm(g131, 30));
    Handwritten26 hw(g26.symbols());
    ModuleString a, b;
    double rhw = rate([&] { return hw.run(14, a, b); });
    double f124 = rate(interp(g124a, 5), 3);
    double f26 = rate(interp(g26, 14), 3);
    double f131 = rate(interp(g131, 30), 3);
    double fhw = rate(
        [&] {
          ModuleString x, y;  // fresh buffers, as a new Deriver starts with
          return hw.run(14, x, y);
        },
        3);

    // Cross-check: the hand-written rewrite yields the interpreter's string.
    if (formatModuleString(a, g26.symbols()) != formatModuleString(derive(g26, o26), g26.symbols())) {
      std::fprintf(stderr, "hand-written 2.6 differs from the interpreter\n");
      return 1;
    }

    // The cost of context matching itself: one step over the same string (the 1.31a result
    // at n=30) with the 1.31a context-sensitive rules, and with context-free rules for the
    // same symbols rewriting one module into one (0 -> 0, 1 -> 1, + -> -, - -> +); rates in
    // modules read per second, since the two write different numbers of modules.
    DeriveOptions o30;
    o30.steps = 30;
    std::string s131 = formatModuleString(derive(g131, o30), g131.symbols());
    std::string csText = "ignore: +-F\naxiom: " + s131 +
                         "\n0<0>0-->0\n0<0>1-->1[+F1F1]\n0<1>0-->1\n0<1>1-->1\n1<0>0-->0\n1<0>1-->1F1\n1<1>0-->0\n"
                         "1<1>1-->0\n+-->-\n- --> +\n";
    std::string cfText = "axiom: " + s131 + "\n0-->0\n1-->1\n+-->-\n- --> +\n";
    Grammar gcs = parseGrammar(csText, "cs.lsys"), gcf = parseGrammar(cfText, "cf.lsys");
    auto readRate = [&](const Grammar& g) {
      auto d = std::make_shared<Deriver>(g, DeriveOptions{.steps = 1});
      return rate([d, n = g.axiom().size()]() {
        d->restart();
        d->derive();
        return static_cast<uint64_t>(n);
      });
    };
    double rcs = readRate(gcs), rcf = readRate(gcf);

    std::printf("derivation throughput, one thread, CPU time (million modules written per second)\n");
    std::printf("                                                    warm buffers   fresh buffers\n");
    std::printf("  ABOP 1.24a n=5  (%6zu modules) interpreter     %8.1f       %8.1f\n", final124, r124 / 1e6, f124 / 1e6);
    std::printf("  ABOP 2.6   n=14 (%6zu modules) interpreter     %8.1f       %8.1f\n", final26, r26 / 1e6, f26 / 1e6);
    std::printf("  ABOP 2.6   n=14 (%6zu modules) hand-written    %8.1f       %8.1f\n", final26, rhw / 1e6, fhw / 1e6);
    std::printf("  ABOP 1.31a n=30 (%6zu modules) interpreter     %8.1f       %8.1f   (context-sensitive)\n", final131,
                r131 / 1e6, f131 / 1e6);
    std::printf("interpreter / hand-written on 2.6 (warm): 1/%.2f (target: better than 1/8)\n", rhw / r26);
    std::printf("context-sensitive 1.31a vs context-free 1.24a (warm): %.2fx slower (target: at most 3x)\n", r124 / r131);
    std::printf("one step over the 1.31a string, modules read per second: context-sensitive %.1f M/s, context-free %.1f M/s: %.2fx slower\n",
                rcs / 1e6, rcf / 1e6, rcf / rcs);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
