#include "model/growth.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "core/phases.h"
#include "core/progress.h"
#include "model/tree_kind.h"

namespace sprig {

DBox3 framingBox(const lsystem::Skeleton& skeleton) {
  DBox3 b = skeleton.bounds();
  if (b.empty()) return DBox3{DVec3(-0.5), DVec3(0.5)};
  return b;
}

GrowthEngine::GrowthEngine(const Species& species, const GrowthOptions& options)
    : progressLabel_(options.progressLabel) {
  const TreeSpec& tree = treeSpec(species);
  grammar_ = std::make_unique<lsystem::Grammar>(speciesGrammar(species, options.extra));
  turtle_ = speciesTurtle(species, *grammar_);
  lsystem::DeriveOptions dopt;
  dopt.maxModules = tree.maxModules;
  dopt.trackBirthSteps = true;
  dopt.queryTurtle = turtle_;  // cpfg's query modules see the turtle that draws the tree
  // cpfg -g draws no final string when the view file sets the view volume (`box:`)
  dopt.queriesAfterLastStep = !(tree.view && tree.view->box);
  if (tree.view) unsupportedDrawing_ = tree.view->unsupportedDrawing;
  dopt.environmentAfterEachStep = tree.view && tree.view->environmentBefore;
  if (!options.extra.cpfgEnvironment.empty()) {
    // cpfg runs the program in the object's folder, where the grammar is
    std::string dir = std::filesystem::path(grammar_->fileName()).parent_path().string();
    if (dir.empty()) dir = ".";
    lsystem::EnvironmentOptions eo;
    eo.timeoutSeconds = options.extra.cpfgEnvironmentTimeout;
    dopt.environment = std::make_shared<lsystem::EnvironmentProgram>(
        lsystem::readEnvironmentFile(options.extra.cpfgEnvironment), std::filesystem::absolute(dir).string(), eo);
  }
  deriver_ = std::make_unique<lsystem::Deriver>(*grammar_, dopt);
  lastStep_ = options.lastStep < 0 ? deriver_->steps() : std::min(options.lastStep, deriver_->steps());
}

GrowthEngine::~GrowthEngine() = default;

uint64_t GrowthEngine::seed() const { return deriver_->seed(); }

const lsystem::SymbolTable& GrowthEngine::symbols() const { return deriver_->symbols(); }

void GrowthEngine::advanceTo(int step) {
  const Phase phase("derive");
  if (step < 0 || step > lastStep_)
    throw std::invalid_argument("step " + std::to_string(step) + " is outside 0.." + std::to_string(lastStep_));
  if (interpretedStep_ == step) return;
  if (deriver_->stepsDone() > step) deriver_->restart();
  std::optional<Progress> bar;
  if (!progressLabel_.empty() && deriver_->stepsDone() < step)
    bar.emplace(progressLabel_, static_cast<uint64_t>(step - deriver_->stepsDone()));
  while (deriver_->stepsDone() < step) {
    if (ProgressSettings::cancelRequested()) throw Cancelled();
    deriver_->step();
    if (bar) bar->advance();
  }
  if (bar) bar->finish();
  if (deriver_->hasInterpretation()) interpreted_ = deriver_->interpret(deriver_->current());
  interpretedStep_ = step;
}

const lsystem::ModuleString& GrowthEngine::interpreted() const {
  return deriver_->hasInterpretation() ? interpreted_ : deriver_->current();
}

namespace {

size_t bytesOf(const lsystem::ModuleString& s) {
  return s.symbols.size() * sizeof(lsystem::SymbolId) + s.offsets.size() * sizeof(s.offsets[0]) +
         s.params.size() * sizeof(double) + s.birthSteps.size() * sizeof(s.birthSteps[0]);
}

}  // namespace

void GrowthEngine::measure() {
  if (measured_) return;
  const Phase phase("derive");
  size_t snapshotBytes = 0;
  bool keep = true;
  // One pass over every step: the camera's box, and each step's growthStart from the
  // internode lengths (old modules, new modules) against the previous step's total.
  start_.assign(static_cast<size_t>(lastStep_) + 1, 0.0);
  double previousLength = 0;
  for (int step = 0; step <= lastStep_; ++step) {
    if (ProgressSettings::cancelRequested()) throw Cancelled();
    advanceTo(step);
    moduleCounts_.push_back(deriver_->current().size());
    snapshotBytes += bytesOf(interpreted());
    keep = keep && snapshotBytes <= kSnapshotBytes;
    if (keep) snapshots_.push_back(interpreted());
    lsystem::Skeleton sk = draw(interpreted(), turtle_, nullptr);
    const DBox3 b = framingBox(sk);
    frameBox_ = step == 0 ? b : DBox3{glm::min(frameBox_.lo, b.lo), glm::max(frameBox_.hi, b.hi)};
    double oldLength = 0, newLength = 0;
    for (const auto& in : sk.internodes) (in.step < step ? oldLength : newLength) += in.length();
    if (step > 0 && newLength > 0) start_[step] = std::clamp((previousLength - oldLength) / newLength, 0.0, 1.0);
    previousLength = oldLength + newLength;
  }
  if (!keep) snapshots_.clear();
  measured_ = true;
}

const DBox3& GrowthEngine::frameBox() {
  measure();
  return frameBox_;
}

double GrowthEngine::growthStart(int step) {
  measure();
  return step >= 0 && step <= lastStep_ ? start_[static_cast<size_t>(step)] : 0.0;
}

const lsystem::ModuleString& GrowthEngine::modulesAt(int step) {
  advanceTo(step);
  return deriver_->current();
}

const lsystem::ModuleString& GrowthEngine::interpretedAt(int step) {
  if (static_cast<size_t>(step) < snapshots_.size() && step >= 0) return snapshots_[static_cast<size_t>(step)];
  advanceTo(step);
  return interpreted();
}

size_t GrowthEngine::moduleCount(int step) {
  if (step >= 0 && static_cast<size_t>(step) < moduleCounts_.size()) return moduleCounts_[static_cast<size_t>(step)];
  return modulesAt(step).size();
}

void GrowthEngine::refuseDrawing() const {
  if (unsupportedDrawing_) throw InputError(std::vector<Diagnostic>{*unsupportedDrawing_});
}

lsystem::Skeleton GrowthEngine::draw(const lsystem::ModuleString& interpreted, const lsystem::TurtleSettings& settings,
                                     lsystem::TurtleState* end) {
  refuseDrawing();
  const Phase phase("derive");
  lsystem::Turtle turtle(deriver_->symbols(), settings);
  lsystem::Skeleton sk = turtle.run(interpreted, interpreted.birthSteps);
  if (end) *end = turtle.endState();
  return sk;
}

lsystem::Skeleton GrowthEngine::skeletonAt(int step, lsystem::TurtleState* end) {
  if (step < 0 || step > lastStep_)
    throw std::invalid_argument("step " + std::to_string(step) + " is outside 0.." + std::to_string(lastStep_));
  return draw(interpretedAt(step), turtle_, end);
}

lsystem::SkeletonSummary GrowthEngine::summaryAt(int step, lsystem::TurtleState* end) {
  if (step < 0 || step > lastStep_)
    throw std::invalid_argument("step " + std::to_string(step) + " is outside 0.." + std::to_string(lastStep_));
  refuseDrawing();
  const Phase phase("derive");
  const lsystem::ModuleString& interpreted = interpretedAt(step);
  lsystem::Turtle turtle(deriver_->symbols(), turtle_);
  lsystem::SkeletonSummary sum = turtle.summarize(interpreted, interpreted.birthSteps);
  if (end) *end = turtle.endState();
  return sum;
}

lsystem::Skeleton GrowthEngine::skeletonAt(int step, double fraction) {
  lsystem::TurtleSettings ts = turtle_;
  ts.growthStep = step;
  ts.growthFraction = fraction;
  ts.growthStart = growthStart(step);
  if (step < 0 || step > lastStep_)
    throw std::invalid_argument("step " + std::to_string(step) + " is outside 0.." + std::to_string(lastStep_));
  return draw(interpretedAt(step), ts, nullptr);
}

}  // namespace sprig
