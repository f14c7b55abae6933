#pragma once
/// The subcommands of the `sprig` binary, one `cmd_<verb>.cpp` each.
///
/// main.cpp builds the CLI11 application, asks each add*Command to register its
/// subcommand, parses the command line and then calls the chosen command's run function.
/// A run function returns the exit code (0 success); bad input throws InputError (exit 1),
/// a bad flag value throws UsageError (exit 2), anything else is an internal error (3).

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <utility>
#include <stdexcept>
#include <string>

#include "core/diagnostics.h"
#include "model/yaml_reader.h"

namespace sprig {

/// Exit codes of `sprig`.
enum ExitCode : int { kExitOk = 0, kExitBadInput = 1, kExitUsage = 2, kExitInternal = 3 };

/// Options every subcommand shares (`--quiet`, `--threads`, `--root`, `--allow-outside-paths`,
/// `--full-tape`, `--timings`).
struct GlobalOptions {
  bool quiet = false;
  int threads = 0;  ///< 0 = all cores
  std::string root;  ///< `--root`; empty: each species file's defaultLibraryRoot
  bool allowOutsidePaths = false;
  bool fullTape = false;  ///< `--full-tape`: implicit surfaces trace the whole tape per cell
  bool strict = false;    ///< `--strict`: warnings about the input are errors
  std::string timings = "text";  ///< `--timings text|json|none`: the phases printed after the command

  /// Where species files may reference files from.
  PathPolicy pathPolicy() const {
    PathPolicy p;
    p.root = root;
    p.allowOutside = allowOutsidePaths;
    return p;
  }
};

/// What main calls after parsing when a subcommand was chosen.
using CommandRun = std::function<int()>;

/// `sprig derive FILE ...` (app/cmd_derive.cpp).
void addDeriveCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);
/// `sprig check FILE...` (app/cmd_check.cpp).
void addCheckCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);
/// `sprig preview FILE -o OUT` (app/cmd_preview.cpp).
void addPreviewCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);
/// `sprig gallery [FILES...] -o DIR` (app/cmd_gallery.cpp).
void addGalleryCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);
/// `sprig animate SPECIES -o OUT` (app/cmd_animate.cpp).
void addAnimateCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);

/// `sprig schema [-o FILE]` (app/cmd_schema.cpp).
void addSchemaCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);

/// `sprig render SPECIES -o OUT` (app/cmd_render.cpp).
void addRenderCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run);

/// Registers the required input `name` (a species file or grammar) and output `-o`.
void addInputOutput(CLI::App& sub, const char* name, std::string& file, std::string& out, const char* outputHelp);
/// addInputOutput with an -o that may be given several times (`-o a.glb -o b.obj`), each
/// occurrence taking one path.
void addInputOutputs(CLI::App& sub, const char* name, std::string& file, std::vector<std::string>& outs, const char* outputHelp);

/// Registers subcommand `name`: its flags fill an Args (returned for the caller to bind),
/// and choosing it makes `run` call body(args, global).
template <class Args>
std::pair<CLI::App*, std::shared_ptr<Args>> subcommand(CLI::App& app, const GlobalOptions& global, CommandRun& run,
                                                       const char* name, const char* description,
                                                       int (*body)(const Args&, const GlobalOptions&)) {
  auto args = std::make_shared<Args>();
  CLI::App* sub = app.add_subcommand(name, description);
  sub->callback([args, body, &global, &run] { run = [args, body, &global] { return body(*args, global); }; });
  return {sub, args};
}

/// Throws UsageError unless path's extension is one of `allowed` (lower case, with dot).
void requireExtension(const std::string& flag, const std::string& path, std::initializer_list<const char*> allowed);

}  // namespace sprig
