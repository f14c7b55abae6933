/// `sprig check FILE...`: validates species files and grammars, printing every diagnostic.

#include <iostream>

#include "app/cmd_common.h"
#include "model/kinds.h"
#include "model/species.h"

namespace sprig {

namespace {

struct CheckArgs {
  std::vector<std::string> files;
};

/// Checks one file; returns the diagnostics text (empty when it is fine).
std::string checkOne(const std::string& file, const GlobalOptions& g, std::string& summary) {
  try {
    // Loading reads every section of the species (and its grammar) and reports every error.
    Species s = loadSpecies(file, g.pathPolicy());
    if (!s.spec) throw InputError(s.loc(), "invalid " + s.kind + " species");  // (every reader says why first)
    printNotes(g, s);
    summary = s.kind + (s.bareGrammar ? " grammar" : " species") + s.spec->checkSummary(s);
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
  auto [sub, args] = subcommand<CheckArgs>(app, global, run, "check",
                                          "Validate species files and grammars, printing every diagnostic", runCheck);
  sub->add_option("FILE", args->files, "species files (.yaml), grammars (.lsys, cpfg's .l) or vlab object folders")->required();
}

}  // namespace sprig
