/// Turtle interpretation throughput on large ABOP strings (one core).
///
/// Builds ABOP figure 1.24a (n = 9) and figure 2.6a (n = 18) strings with hand-written
/// rewriting (so the benchmark measures only the turtle), then times Turtle::run against
/// a baseline loop that only walks the same arrays (symbol, offsets, first parameter).
/// Prints modules per CPU-second (thread CPU time, robust on a busy machine) for both and
/// their ratio. Usage: bench_turtle [repeats]

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <string_view>

#include "lsystem/turtle.h"

using namespace sprig;
using namespace sprig::lsystem;

namespace {

struct Case {
  const char* name;
  SymbolTable table;
  ModuleString string;
  double angleDeg = 90;
};

void pushText(ModuleString& out, SymbolTable& t, std::string_view text) {
  for (char c : text) out.push(t.intern(std::string_view(&c, 1)));
}

/// ABOP 1.24a: F -> F[+F]F[-F]F, n steps.
Case figure124a(int n) {
  Case c{"ABOP 1.24a"};
  c.angleDeg = 25.7;
  pushText(c.string, c.table, "F");
  SymbolId f = static_cast<SymbolId>(c.table.find("F"));
  for (int s = 0; s < n; ++s) {
    ModuleString next;
    next.reserve(c.string.size() * 5, 0);
    for (size_t i = 0; i < c.string.size(); ++i) {
      if (c.string.symbols[i] == f) {
        pushText(next, c.table, "F[+F]F[-F]F");
      } else {
        next.push(c.string.symbols[i]);
      }
    }
    c.string = std::move(next);
  }
  return c;
}

/// ABOP 2.6a: A(l,w) -> !(w)F(l)[&(45)B(l*.6,w*.707)]/(137.5)A(l*.9,w*.707),
/// B(l,w) -> !(w)F(l)[-(45)$C(l*.6,w*.707)]C(l*.9,w*.707),
/// C(l,w) -> !(w)F(l)[+(45)$B(l*.6,w*.707)]B(l*.9,w*.707); n steps.
Case figure26(int n) {
  Case c{"ABOP 2.6a"};
  SymbolTable& t = c.table;
  const SymbolId A = t.intern("A"), B = t.intern("B"), C = t.intern("C"), W = t.intern("!"), F = t.intern("F"),
                 L = t.intern("["), R = t.intern("]"), amp = t.intern("&"), sl = t.intern("/"),
                 minus = t.intern("-"), plus = t.intern("+"), dollar = t.intern("$");
  const double r1 = 0.9, r2 = 0.6, wr = 0.707;
  double ax[2] = {1, 10};
  c.string.push(A, ax);
  for (int s = 0; s < n; ++s) {
    ModuleString next;
    next.reserve(c.string.size() * 5, c.string.params.size() * 5);
    for (size_t i = 0; i < c.string.size(); ++i) {
      SymbolId sym = c.string.symbols[i];
      if (sym != A && sym != B && sym != C) {
        next.push(sym, c.string.paramsOf(i));
        continue;
      }
      double l = c.string.paramsOf(i)[0], w = c.string.paramsOf(i)[1];
      double pw[1] = {w}, pl[1] = {l}, side[2] = {l * r2, w * wr}, main[2] = {l * r1, w * wr};
      next.push(W, pw);
      next.push(F, pl);
      next.push(L);
      if (sym == A) {
        double a0[1] = {45}, d[1] = {137.5};
        next.push(amp, a0);
        next.push(B, side);
        next.push(R);
        next.push(sl, d);
        next.push(A, main);
      } else {
        double a2[1] = {45};
        next.push(sym == B ? minus : plus, a2);
        next.push(dollar);
        next.push(sym == B ? C : B, side);
        next.push(R);
        next.push(sym == B ? C : B, main);
      }
    }
    c.string = std::move(next);
  }
  return c;
}

/// This thread's CPU time in seconds: unlike wall time it does not count the time the
/// thread waits for a core, so numbers stay comparable on a busy machine.
double cpuNow() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double seconds(double a, double b) { return b - a; }

}  // namespace

int main(int argc, char** argv) {
  int repeats = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  for (Case* c : {new Case(figure124a(9)), new Case(figure26(18))}) {
    const ModuleString& ms = c->string;
    TurtleSettings settings;
    settings.angleDeg = c->angleDeg;
    Turtle turtle(c->table, settings);

    double bestWalk = 1e30, bestTurtle = 1e30, bestReuse = 1e30;
    double sink = 0;
    size_t internodes = 0;
    Skeleton reused;
    for (int r = 0; r < repeats; ++r) {
      // Baseline: walk the string touching what the turtle reads, doing nothing else.
      auto t0 = cpuNow();
      double acc = 0;
      for (size_t i = 0; i < ms.size(); ++i) {
        acc += ms.symbols[i];
        if (ms.offsets[i + 1] > ms.offsets[i]) acc += ms.params[ms.offsets[i]];
      }
      auto t1 = cpuNow();
      Skeleton sk = turtle.run(ms);
      auto t2 = cpuNow();
      turtle.run(ms, reused);
      auto t3 = cpuNow();
      bestReuse = std::min(bestReuse, seconds(t2, t3));
      sink += acc + sk.internodes.back().end.y + reused.internodes.back().end.y;
      internodes = sk.internodes.size();
      bestWalk = std::min(bestWalk, seconds(t0, t1));
      bestTurtle = std::min(bestTurtle, seconds(t1, t2));
    }
    double n = static_cast<double>(ms.size());
    std::printf("%s: %zu modules, %zu internodes\n", c->name, ms.size(), internodes);
    std::printf("  turtle, fresh skeleton   %7.1f M modules/s (%.4f s)\n", n / bestTurtle * 1e-6, bestTurtle);
    std::printf("  turtle, reused skeleton  %7.1f M modules/s (%.4f s)\n", n / bestReuse * 1e-6, bestReuse);
    std::printf("  baseline walk            %7.1f M modules/s (%.4f s)\n", n / bestWalk * 1e-6, bestWalk);
    std::printf("  ratio turtle/walk time: fresh %.1fx, reused %.1fx%s\n", bestTurtle / bestWalk, bestReuse / bestWalk,
                sink == 0.5 ? " " : "");
    delete c;
  }
  return 0;
}
