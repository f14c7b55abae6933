#include "app/tree_pipeline.h"

#include <algorithm>

#include "core/progress.h"
#include "core/timer.h"

namespace sprig {

namespace {

}  // namespace

GrownTree growTree(const Species& species, const GrowOptions& options) {
  GrownTree out;
  out.grammar = speciesGrammar(species, options.extra);
  lsystem::DeriveOptions dopt;
  dopt.maxModules = species.maxModules;
  dopt.trackBirthSteps = true;
  lsystem::Deriver deriver(out.grammar, dopt);
  out.steps = deriver.steps();
  out.seed = deriver.seed();
  const lsystem::TurtleSettings turtleSettings = speciesTurtle(species, out.grammar);

  auto draw = [&](const lsystem::ModuleString& s, lsystem::TurtleState* end) {
    auto t0 = std::chrono::steady_clock::now();
    lsystem::ModuleString interpreted = deriver.interpret(s);
    lsystem::Turtle turtle(deriver.symbols(), turtleSettings);
    lsystem::Skeleton sk = turtle.run(interpreted, interpreted.birthSteps);
    if (end) *end = turtle.endState();
    out.turtleSeconds += secondsSince(t0);
    return sk;
  };

  std::vector<int> wanted = options.stageSteps;
  out.stages.resize(wanted.size());
  auto snapshot = [&](int step) {
    for (size_t i = 0; i < wanted.size(); ++i)
      if (std::min(wanted[i], out.steps) == step) {
        out.stages[i].step = step;
        out.stages[i].modules = deriver.current().size();
        out.stages[i].skeleton = draw(deriver.current(), nullptr);
      }
  };

  {
    Progress bar("derive " + species.name, static_cast<uint64_t>(out.steps));
    snapshot(0);
    for (int k = 1; k <= out.steps; ++k) {
      if (ProgressSettings::cancelRequested()) throw Cancelled();
      auto t1 = std::chrono::steady_clock::now();
      deriver.step();
      out.deriveSeconds += secondsSince(t1);
      if (options.progress) bar.advance();
      snapshot(k);
    }
    bar.finish();
  }
  out.modules = deriver.current();
  out.symbols = deriver.symbols();
  out.skeleton = draw(out.modules, &out.end);
  return out;
}

}  // namespace sprig
