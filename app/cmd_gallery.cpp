/// `sprig gallery [FILES...] -o DIR [--quality draft|final]`

#include <cstdlib>
#include <iostream>

#include "app/cmd_common.h"
#include "gallery/gallery.h"
#include "gallery/shard.h"
#include "model/species.h"
#include "core/atomic_file.h"
#include "core/progress.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

struct GalleryArgs {
  std::vector<std::string> files;
  std::string out;
  std::string quality = "draft";
  std::string shard;  ///< `--shard I/N`
  std::string merge;  ///< `--merge DIR`
};

int runGallery(const GalleryArgs& a, const GlobalOptions& g) {
  if (!a.merge.empty()) {
    if (!fs::is_directory(a.merge)) throw UsageError("--merge " + a.merge + ": no such gallery folder");
    size_t n = 0;
    try {
      n = mergeGallery(a.merge);
    } catch (const std::runtime_error& e) {
      throw UsageError(e.what());
    }
    if (!g.quiet) std::cerr << (fs::path(a.merge) / "index.html").string() << ": " << n << " species\n";
    return kExitOk;
  }
  if (a.out.empty()) throw UsageError("gallery: -o DIR is required (or --merge DIR)");
  // The shard: --shard, else the job array's environment, else the whole gallery.
  Shard shard;
  if (!a.shard.empty()) {
    shard = parseShard(a.shard);
  } else if (auto env = shardFromEnvironment([](const char* name) { return std::getenv(name); })) {
    shard = *env;
  }
  std::vector<fs::path> files(a.files.begin(), a.files.end());
  if (files.empty()) files = listSpeciesFiles(fs::path(g.root) / "species");
  if (files.empty()) throw UsageError("no species files given and none found in " + (fs::path(g.root) / "species").string());
  // Check every species before anything is written: a bad input leaves no file behind.
  int bad = 0;
  for (const fs::path& f : files) {
    try {
      loadSpecies(f, g.pathPolicy());  // reads every section, the grammar included
    } catch (const InputError& e) {
      std::cerr << e.what() << "\n";
      ++bad;
    }
  }
  if (bad) return kExitBadInput;

  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec || !fs::is_directory(a.out)) throw UsageError("-o " + a.out + ": cannot create the gallery folder");
  GalleryRunOptions run;
  run.quality = a.quality == "final" ? GalleryQuality::Final : GalleryQuality::Draft;
  run.shard = shard;
  run.quiet = g.quiet;
  const GalleryRunResult r = renderGallery(files, a.out, run, g.pathPolicy());
  if (!g.quiet)
    std::cerr << a.out << ": shard " << shard.index << "/" << shard.count << ": " << r.rendered << " rendered, "
              << r.skipped << " up to date, " << r.failed << " failed"
              << (shard.count == 1 ? ", index.html written" : ", merge with --merge") << "\n";
  return r.failed ? kExitBadInput : kExitOk;
}

}  // namespace

void addGalleryCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto [sub, args] = subcommand<GalleryArgs>(app, global, run, "gallery",
                                          "Render every species (default: species/*.yaml) and write index.html", runGallery);
  sub->add_option("FILES", args->files, "species files (default: all in ROOT/species)");
  sub->add_option("-o,--output", args->out, "gallery folder (required unless --merge)");
  sub->add_option("--quality", args->quality, "draft (fast, small) or final (species' own size and samples)")
      ->check(CLI::IsMember({"draft", "final"}));
  sub->add_option("--shard", args->shard,
                  "render only shard I of N (I/N, from 0; default from SLURM_ARRAY_TASK_ID/COUNT or "
                  "JOB_COMPLETION_INDEX and SPRIG_SHARD_COUNT)");
  sub->add_option("--merge", args->merge, "build DIR/index.html and the contact sheet from DIR's shard manifests");
}

}  // namespace sprig
