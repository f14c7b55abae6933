/// `sprig gallery [FILES...] -o DIR [--quality draft|final]`

#include <iostream>

#include "app/cmd_common.h"
#include "app/gallery.h"
#include "app/species.h"
#include "core/atomic_file.h"
#include "core/progress.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

struct GalleryArgs {
  std::vector<std::string> files;
  std::string out;
  std::string quality = "draft";
};

int runGallery(const GalleryArgs& a, const GlobalOptions& g) {
  std::vector<fs::path> files(a.files.begin(), a.files.end());
  if (files.empty()) files = listSpeciesFiles(fs::path(g.root) / "species");
  if (files.empty()) throw UsageError("no species files given and none found in " + (fs::path(g.root) / "species").string());
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec || !fs::is_directory(a.out)) throw UsageError("-o " + a.out + ": cannot create the gallery folder");
  removeStaleTemporaries(a.out);
  const GalleryQuality quality = a.quality == "final" ? GalleryQuality::Final : GalleryQuality::Draft;

  std::vector<GalleryItem> items;
  int failed = 0;
  for (const fs::path& f : files) {
    GalleryItem item = renderGalleryItem(f, a.out, quality, g.pathPolicy());
    if (!item.error.empty()) {
      ++failed;
      std::cerr << item.error << "\n";
    } else if (!g.quiet) {
      std::cerr << f.string() << ": " << item.modules << " modules, " << item.internodes << " internodes, "
                << item.renderSeconds << " s render\n";
    }
    items.push_back(std::move(item));
  }
  writeFileAtomic(fs::path(a.out) / "index.html", galleryIndexHtml(items));
  if (!g.quiet) std::cerr << (fs::path(a.out) / "index.html").string() << ": " << items.size() << " species\n";
  return failed ? kExitBadInput : kExitOk;
}

}  // namespace

void addGalleryCommand(CLI::App& app, const GlobalOptions& global, CommandRun& run) {
  auto args = std::make_shared<GalleryArgs>();
  CLI::App* sub = app.add_subcommand("gallery", "Render every species (default: species/*.yaml) and write index.html");
  sub->add_option("FILES", args->files, "species files (default: all in ROOT/species)");
  sub->add_option("-o,--output", args->out, "gallery folder")->required();
  sub->add_option("--quality", args->quality, "draft (fast, small) or final (species' own size and samples)")
      ->check(CLI::IsMember({"draft", "final"}));
  sub->callback([args, &global, &run] { run = [args, &global] { return runGallery(*args, global); }; });
}

}  // namespace sprig
