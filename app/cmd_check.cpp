/// `sprig check FILE...`: validates species files and grammars, printing every diagnostic.

#include <iostream>

#include "app/cmd_common.h"
#include "app/model.h"
#include "app/species.h"
#include "app/species_tree.h"

namespace sprig {

namespace {

struct CheckArgs {
  std::vector<std::string> files;
};

/// Checks one file; returns the diagnostics text (empty when it is fine).
std::string checkOne(const std::string& file, const GlobalOptions& g, std::string& summary) {
  try {
    Species s = loadSpecies(file, g.pathPolicy());
    summary = std::string(speciesKindName(s.kind)) + (s.bareGrammar ? " grammar" : " species");
    if (s.kind == SpeciesKind::Tree) {
      lsystem::Grammar grammar = speciesGrammar(s);
      summary += " '" + s.name + "', " + std::to_string(grammar.productionCount()) + " productions, " +
                 std::to_string(grammar.derivationLength()) + " steps";
      if (s.treeSection) {
        DiagnosticList diags;
        readTreeOptions(*s.treeSection, diags);
        diags.throwIfErrors();
        summary += ", BlobTree surface";
      }
    } else {
      // Shells and blobs: read their sections and build the final model (cheap for both),
      // so builder errors such as invalid parameters show here too.
      SpeciesModel model(s);
      model.frameBox();
      summary += " '" + s.name + "'";
    }
    return {};
  } catch (const InputError& e) {
    return e.what();
  }
}

int runCheck(const CheckArgs& a, const GlobalOptions& g) {
  int bad = 0;
  for (const std::string& f : a.files) {
    std::string summary;
    std::string errors = checkOne(f, g, summary);
    if (errors.empty()) {
      if (!g.quiet) std::cout << f << ": ok (" << summary << ")\n";
    } else {
      ++bad;
      std::cerr << errors << "\n";
    }
  }
  if (bad && a.files.size() > 1) std::cerr << bad << " of " << a.files.size() << " files have errors\n";
  return bad ? kExitBadInput : kExitOk;
}

}  // namespace

void addCheckCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App* sub = app.add_subcommand("check", "Validate species files and grammars, printing every diagnostic");
  sub->add_option("FILE", args->files, "species files (.yaml) or grammars (.lsys)")->required();
  sub->callback([args, &global, &run] { run = [args, &global] { return runCheck(*args, global); }; });
}

}  // namespace sprig
