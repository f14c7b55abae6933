/// `sprig derive FILE [--steps N] [--seed S] [-D NAME=VALUE] [--print] [--json] [--skeleton OUT.json]`

#include <iostream>
#include <map>
#include <sstream>

#include "app/cmd_common.h"
#include "core/json_writer.h"
#include "model/species.h"
#include "model/growth.h"
#include "model/tree_kind.h"
#include "core/atomic_file.h"
#include "lsystem/derive.h"

namespace sprig {

namespace {

struct DeriveArgs {
  std::string file;
  GrowthFlags growth;
  bool print = false;
  bool json = false;
  std::string skeletonOut;
};

/// What `sprig derive` reports: the final string, its skeleton's summary and (for
/// --skeleton only: 112 bytes per internode) the skeleton itself.
struct Derived {
  int steps = 0;
  uint64_t seed = 0;
  const lsystem::ModuleString& modules;
  const lsystem::SymbolTable& symbols;
  lsystem::SkeletonSummary summary;
  lsystem::Skeleton skeleton;
  lsystem::TurtleState end;
};

/// The `--json` report: steps, modules, symbol counts, internodes, total length, bounds, end.
std::string reportJson(const Derived& t) {
  std::vector<size_t> counts(t.symbols.size(), 0);
  for (lsystem::SymbolId s : t.modules.symbols) ++counts[s];
  std::ostringstream o;
  o << "{\"steps\": " << t.steps << ", \"modules\": " << t.modules.size() << ", \"symbols\": {";
  bool first = true;
  for (size_t s = 0; s < counts.size(); ++s) {
    if (!counts[s]) continue;
    o << (first ? "" : ", ") << json::string(t.symbols.name(static_cast<lsystem::SymbolId>(s))) << ": " << counts[s];
    first = false;
  }
  DBox3 b = t.summary.bounds;
  if (b.empty()) b = DBox3{DVec3(0), DVec3(0)};
  o << "}, \"internodes\": " << t.summary.internodes
    << ", \"total_length\": " << json::number(t.summary.totalLength) << ", \"bounds\": {\"min\": " << json::vec3(b.lo)
    << ", \"max\": " << json::vec3(b.hi) << "}, \"end\": " << json::vec3(t.end.frame.position) << "}";
  return o.str();
}

/// The `--skeleton` file: every internode and a summary of organs.
std::string skeletonJson(const Derived& t) {
  std::string out;
  out.reserve(t.skeleton.internodes.size() * 160 + 256);
  out += "{\"steps\": " + std::to_string(t.steps) + ", \"seed\": " + std::to_string(t.seed) + ",\n \"internodes\": [";
  for (size_t i = 0; i < t.skeleton.internodes.size(); ++i) {
    const auto& n = t.skeleton.internodes[i];
    out += i ? ",\n  " : "\n  ";
    out += "{\"start\": " + json::vec3(n.start) + ", \"end\": " + json::vec3(n.end) +
           ", \"base_radius\": " + json::number(n.baseRadius) + ", \"tip_radius\": " + json::number(n.tipRadius) +
           ", \"parent\": " + std::to_string(n.parent) + ", \"order\": " + std::to_string(n.order) +
           ", \"step\": " + std::to_string(n.step) + "}";
  }
  out += "],\n \"organs\": [";
  static const char* kinds[] = {"polygon", "sphere", "surface"};
  for (size_t i = 0; i < t.skeleton.organs.size(); ++i) {
    const auto& g = t.skeleton.organs[i];
    out += i ? ",\n  " : "\n  ";
    out += "{\"kind\": \"" + std::string(kinds[static_cast<int>(g.kind)]) + "\", \"position\": " +
           json::vec3(g.position) + ", \"radius\": " + json::number(g.radius) +
           ", \"internode\": " + std::to_string(g.internode) + ", \"step\": " + std::to_string(g.step);
    if (g.kind == lsystem::Organ::Kind::Polygon) {
      out += ", \"points\": [";
      for (size_t k = 0; k < g.points.size(); ++k) out += (k ? ", " : "") + json::vec3(g.points[k]);
      out += "]";
    }
    if (g.kind == lsystem::Organ::Kind::Surface) out += ", \"name\": " + json::string(g.name);
    out += "}";
  }
  out += "]}\n";
  return out;
}

int runDerive(const DeriveArgs& a, const GlobalOptions& g) {
  if (!a.skeletonOut.empty()) requireExtension("--skeleton", a.skeletonOut, {".json"});
  lsystem::GrammarOverrides extra = a.growth.overrides();
  Species species = loadSpecies(a.file, g.pathPolicy());
  printNotes(g, species);
  GrowthEngine engine(species, GrowthOptions{extra, -1, "derive " + species.name});
  if (a.growth.environment.empty() && engine.symbols().find("?E") >= 0 && !g.quiet)
    std::cerr << "sprig: warning: the grammar's ?E modules keep their values, as cpfg's do without an environmental "
                 "program (give one with -e FILE.e)\n";
  const int last = engine.lastStep();
  const lsystem::ModuleString& modules = engine.modulesAt(last);
  Derived t{last, engine.seed(), modules, engine.symbols(), {}, {}, {}};
  // --print alone draws nothing: the string does not need the turtle (so a view file
  // command Sprig cannot draw, such as cpfg's 'line:', does not stop it).
  const bool drawn = a.json || !a.print || !a.skeletonOut.empty();
  if (drawn && a.skeletonOut.empty()) {
    t.summary = engine.summaryAt(last, &t.end);
  } else if (drawn) {
    t.skeleton = engine.skeletonAt(last, &t.end);
    t.summary = {t.skeleton.internodes.size(), t.skeleton.totalLength(), t.skeleton.bounds(), {}};
  }
  if (a.print) {
    std::cout << lsystem::formatModuleString(t.modules, t.symbols, speciesStringFormat(species)) << "\n";
  }
  if (a.json) std::cout << reportJson(t) << "\n";
  if (!a.print && !a.json)
    std::cout << species.name << ": " << t.steps << " steps, " << t.modules.size() << " modules, "
              << t.summary.internodes << " internodes, total length " << json::number(t.summary.totalLength)
              << "\n";
  if (!a.skeletonOut.empty()) writeFileAtomic(a.skeletonOut, skeletonJson(t));
  return kExitOk;
}

}  // namespace

void addDeriveCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<DeriveArgs>(app, global, run, "derive",
                                          "Derive a grammar or tree species and report the result", runDerive);
  sub->add_option("FILE", args->file, "species file (.yaml), grammar (.lsys, cpfg's .l) or vlab object folder")->required();
  addGrowthFlags(*sub, args->growth);
  sub->add_flag("--print", args->print, "print the final module string in grammar notation");
  sub->add_flag("--json", args->json, "print a JSON report (steps, modules, symbols, internodes, ...)");
  sub->add_option("--skeleton", args->skeletonOut, "write every internode to this JSON file");
}

}  // namespace sprig
