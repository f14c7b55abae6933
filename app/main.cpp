/// The `sprig` command-line tool: parses the command line and runs one subcommand.
/// Exit codes: 0 success, 1 bad input, 2 bad usage, 3 internal error.

#include <CLI/CLI.hpp>

#include <iostream>

#include "core/atomic_file.h"
#include "core/diagnostics.h"

int main(int argc, char** argv) {
  sprig::installSignalCleanup();
  CLI::App app{"Sprig: procedural botanical modeling", "sprig"};
  app.set_version_flag("--version", SPRIG_VERSION);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  return 0;
}
