#pragma once
/// The sharded, resumable gallery: which species a shard renders, when an item can be
/// skipped, and the run that renders a shard's share and the merge that builds the index.
///
/// Items are the species files sorted by path; shard I of N renders the items whose
/// sorted index is I modulo N. Every item is rendered by renderGalleryItem from its
/// species file alone, so its files are the same bytes whichever shard renders them.
/// Each shard records its items in DIR/manifests/shard-I-of-N.json (app/manifest.h),
/// rewritten after every item, so a killed run resumes where it stopped: an item is
/// skipped when a manifest in DIR lists it with the same input hash (species file,
/// grammar, referenced files such as textures, gallery options, Sprig version) and all
/// its outputs exist. `--merge` reads every manifest and writes index.html and the
/// contact sheet; an unsharded run does the same at its end.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gallery/gallery.h"

namespace sprig {

/// Shard `index` of `count` (0 <= index < count).
struct Shard {
  int index = 0;
  int count = 1;
};

/// Parses `I/N` (0-based I < N, N >= 1). Throws UsageError naming the flag otherwise.
Shard parseShard(std::string_view text);

/// The shard from the environment: (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN) /
/// SLURM_ARRAY_TASK_STEP (MIN 0 and STEP 1 when unset) of SLURM_ARRAY_TASK_COUNT, else
/// Kubernetes' JOB_COMPLETION_INDEX of
/// SPRIG_SHARD_COUNT; nullopt when neither is set. Throws UsageError for malformed
/// values. getenv is a parameter so tests can pass their own.
std::optional<Shard> shardFromEnvironment(const std::function<const char*(const char*)>& getenv);

/// Indices i in [0, itemCount) with i % shard.count == shard.index, ascending.
std::vector<size_t> shardItems(const Shard& shard, size_t itemCount);

/// Hex digest (128 bits, two FNV-1a lanes) of everything an item's images depend on: the
/// species file's bytes, the grammar's text, every other file the species file names
/// (relative to its folder, e.g. textures), `options` and the Sprig version. Unreadable
/// references hash as their name.
std::string galleryInputHash(const std::filesystem::path& speciesFile, std::string_view options);

/// How a gallery run renders.
struct GalleryRunOptions {
  GalleryQuality quality = GalleryQuality::Draft;
  Shard shard;            ///< this process's share
  bool quiet = false;     ///< no per-item summary lines
};

/// What a gallery run did.
struct GalleryRunResult {
  int rendered = 0;  ///< items rendered now
  int skipped = 0;   ///< items whose outputs were up to date
  int failed = 0;    ///< items with an error
};

/// Renders this shard's share of files (sorted by path first) into outDir, skipping
/// up-to-date items, writing the shard's manifest after each item, and, when the run is
/// unsharded (count 1), the index and contact sheet. Throws Cancelled on a signal.
GalleryRunResult renderGallery(std::vector<std::filesystem::path> files, const std::filesystem::path& outDir,
                            const GalleryRunOptions& options, const PathPolicy& policy);

/// Builds outDir/index.html and outDir/contact_sheet.png from every manifest in outDir
/// (an item listed by several manifests: the most recently written manifest wins).
/// Returns the number of items. Throws std::runtime_error when there is no manifest.
size_t mergeGallery(const std::filesystem::path& outDir);

/// Removes `.sprig-tmp-PID-*` leftovers in folder whose process PID is not running on
/// this host and that are older than minAgeSeconds (0: any age). Returns how many.
int removeDeadTemporaries(const std::filesystem::path& folder, double minAgeSeconds);

}  // namespace sprig
