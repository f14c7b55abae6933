/// The `sprig` command-line tool: parses the command line and runs one subcommand.
/// Exit codes: 0 success, 1 bad input, 2 bad usage, 3 internal error.

#include <CLI/CLI.hpp>

#include <iostream>
#include <optional>

#include "app/cmd_mesh.h"
#include "app/commands.h"
#include "core/atomic_file.h"
#include "core/diagnostics.h"
#include "core/parallel.h"
#include "core/phases.h"
#include "core/progress.h"
#include "render/scene.h"

namespace {

/// The command's phases (core/phases.h) as global.timings asks, on stderr: `--timings text`
/// (unless --quiet) or `--timings json`.
void printTimings(const sprig::GlobalOptions& global, const CLI::App& app) {
  using sprig::PhaseClock;
  std::string command;
  for (const CLI::App* sub : app.get_subcommands()) command = sub->get_name();
  if (global.timings == "json") std::cerr << PhaseClock::json(command) << "\n";
  else if (global.timings == "text" && !global.quiet) std::cerr << "sprig " << command << ": " << PhaseClock::summary() << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sprig;
  PhaseClock::start();
  installSignalCleanup();
  CLI::App app{"Sprig: procedural botanical modeling (L-systems, skeletons, BlobTree surfaces, shells)", "sprig"};
  app.set_version_flag("--version", SPRIG_VERSION);
  app.require_subcommand(1);
  app.fallthrough();

  GlobalOptions global;
  app.add_flag("-q,--quiet", global.quiet, "no progress bars or summaries");
  app.add_option("--threads", global.threads, "worker threads (0 = all cores)")->check(CLI::Range(0, 4096));
  app.add_option("--root", global.root,
                 "library root: species may only reference files inside it (default: the nearest folder above the "
                 "species file holding a .sprig-root file or a species/ folder it lies in, else the species file's folder)")
      ->check(CLI::ExistingDirectory);
  app.add_flag("--allow-outside-paths", global.allowOutsidePaths,
               "let species reference absolute paths and files outside the root");
  app.add_flag("--strict", global.strict, "treat warnings about the input (an undeclared multi-letter module name) as errors");
  app.add_flag("--full-tape", global.fullTape,
               "exact renders trace the whole BlobTree tape in every cell instead of its pruned tape (the reference, "
               "for comparing images; slower)");

  app.add_option("--timings", global.timings,
                 "after the command, where its wall time went, phase by phase (read, derive, build, cells, scene, "
                 "render, write, ...) on stderr: text (one line, the default), json (one JSON object: scripts) or none")
      ->check(CLI::IsMember({"text", "json", "none"}));

  CommandRun run;
  addDeriveCommand(app, global, run);
  addCheckCommand(app, global, run);
  addPreviewCommand(app, global, run);
  addRenderCommand(app, global, run);
  addMeshCommand(app, global, run);
  addGalleryCommand(app, global, run);
  addAnimateCommand(app, global, run);
  addSchemaCommand(app, global, run);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "errors" to CLI11 that exit 0: let it print them.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::string command = "sprig";
    for (const CLI::App* sub : app.get_subcommands()) command += " " + sub->get_name();
    std::cerr << "sprig: error: " << e.what() << "\n"
              << "Run '" << command << " --help' for the options.\n";
    return kExitUsage;
  }

  try {
    ProgressSettings::setQuiet(global.quiet);
    std::optional<ThreadLimit> limit;
    if (global.threads > 0) limit.emplace(global.threads);
    render::Scene::setPrunedTapesDefault(!global.fullTape);
    if (!run) return kExitUsage;
    const int code = run();
    printTimings(global, app);
    return code;
  } catch (const InputError& e) {
    std::cerr << e.what() << "\n";
    return kExitBadInput;
  } catch (const UsageError& e) {
    std::cerr << "sprig: error: " << e.what() << "\n";
    return kExitUsage;
  } catch (const Cancelled&) {
    std::cerr << "sprig: cancelled\n";
    return 130;
  } catch (const std::exception& e) {
    std::cerr << "sprig: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
}
