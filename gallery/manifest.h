#pragma once
/// Per-shard gallery manifests (JSON): which items a shard rendered, their figures, input
/// hashes and output files. `sprig gallery --merge` builds the index from them.
///
/// Layout of DIR/manifests/shard-I-of-N.json:
/// ```
/// {"sprig": "0.1.0", "format": 1, "shard": 0, "shards": 2, "quality": "draft",
///  "items": [{"source": "species/shrub.yaml", "hash": "…", "name": "…", "outputs": ["shrub.png", …], …}]}
/// ```

#include <filesystem>
#include <string>
#include <vector>

#include "gallery/gallery.h"
#include "gallery/shard.h"

namespace sprig {

/// One rendered (or failed) item.
struct ManifestEntry {
  GalleryItem item;
  std::string hash;                  ///< galleryInputHash of the item
  std::vector<std::string> outputs;  ///< file names inside the gallery folder
};

/// What one shard wrote.
struct Manifest {
  std::string version = SPRIG_VERSION;
  Shard shard;
  std::string quality = "draft";
  std::vector<ManifestEntry> entries;
};

/// The manifest as JSON text (stable key order, numbers in shortest round-trip form).
std::string manifestJson(const Manifest& manifest);

/// Reads manifest JSON. Throws InputError with displayPath:line:col on malformed text.
Manifest parseManifest(const std::string& text, const std::string& displayPath);

/// DIR/manifests/shard-I-of-N.json.
std::filesystem::path manifestPath(const std::filesystem::path& outDir, const Shard& shard);

/// Every readable manifest in DIR/manifests, oldest first (by modification time, then name).
/// Unreadable or malformed manifests are skipped.
std::vector<Manifest> loadManifests(const std::filesystem::path& outDir);

}  // namespace sprig
