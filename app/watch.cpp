#include "app/watch.h"

#include <chrono>
#include <iostream>

#include "core/diagnostics.h"
#include "core/file_watch.h"
#include "core/progress.h"
#include "model/species.h"

namespace sprig {

void addWatchFlags(CLI::App& sub, WatchFlags& flags) {
  sub.add_flag("--watch", flags.watch,
               "render again whenever the file or a file it references (grammar, meshes, textures, view file) is saved");
  sub.add_option("--watch-max-renders", flags.maxRenders, "with --watch: stop after N renders (0 = never; for scripts)")
      ->check(CLI::Range(0, 1000000));
  sub.add_flag("--watch-poll", flags.poll, "with --watch: check the files every 0.25 s instead of using inotify");
}

int runWatched(const WatchFlags& flags, const GlobalOptions& g, const std::string& file, const std::string& out,
               const std::function<int()>& renderOnce) {
  if (!flags.watch) {
    if (flags.maxRenders > 0 || flags.poll) throw UsageError("--watch-max-renders and --watch-poll need --watch");
    return renderOnce();
  }
  FileWatchOptions options;
  if (flags.poll) options.mode = FileWatchOptions::Mode::Poll;
  FileWatcher watcher(options);
  int code = kExitOk;
  for (int renders = 1;; ++renders) {
    // The inputs are recorded before the render so that a save during it is not missed.
    const std::vector<std::filesystem::path> inputs = speciesInputFiles(file);
    watcher.watch(inputs);
    const auto start = std::chrono::steady_clock::now();
    try {
      code = renderOnce();
    } catch (const InputError& e) {
      std::cerr << e.what() << "\n";
      code = kExitBadInput;
    } catch (const UsageError& e) {
      std::cerr << "sprig: error: " << e.what() << "\n";
      code = kExitUsage;
    } catch (const Cancelled&) {
      throw;
    } catch (const std::exception& e) {
      std::cerr << "sprig: error: " << e.what() << "\n";
      code = kExitInternal;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (code == kExitOk)
      std::cerr << "sprig: watch: render " << renders << " wrote " << out << " in " << seconds << " s\n";
    else
      std::cerr << "sprig: watch: render " << renders << " failed; " << out << " keeps the last good picture\n";
    if (flags.maxRenders > 0 && renders >= flags.maxRenders) return code;
    if (!g.quiet)
      std::cerr << "sprig: watch: waiting for changes to " << inputs.size() << " file" << (inputs.size() == 1 ? "" : "s")
                << (watcher.usesInotify() ? " (inotify)" : " (polling)") << "; Ctrl-C stops\n";
    const std::vector<std::filesystem::path> changed = watcher.waitForChange();
    if (!g.quiet) std::cerr << "sprig: watch: " << changed.front().string() << " changed\n";
  }
}

}  // namespace sprig
