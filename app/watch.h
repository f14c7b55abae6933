#pragma once
/// `--watch` for `sprig preview` and `sprig render`: render again whenever an input is saved.

#include <functional>
#include <string>

#include "app/commands.h"

namespace sprig {

/// `--watch`, `--watch-max-renders N`, `--watch-poll`.
struct WatchFlags {
  bool watch = false;
  int maxRenders = 0;  ///< stop after this many renders, good or bad (0 = never: Ctrl-C ends it)
  bool poll = false;   ///< compare the files' contents every 0.25 s instead of asking inotify
};

/// Registers the watch flags on sub.
void addWatchFlags(CLI::App& sub, WatchFlags& flags);

/// Without flags.watch: returns renderOnce(). With it: renders, then renders again each
/// time the content of `file` or a file it references (model/species.h speciesInputFiles,
/// looked up again after each render) changes. A render that fails on bad input prints
/// its `file:line:col` error, leaves the last good picture at `out` untouched (pictures
/// are written atomically, and only after a successful build) and waits for the next save.
/// Returns the exit code of the last render.
int runWatched(const WatchFlags& flags, const GlobalOptions& g, const std::string& file, const std::string& out,
               const std::function<int()>& renderOnce);

}  // namespace sprig
