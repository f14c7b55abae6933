#include "gallery/shard.h"

#include <signal.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <iostream>
#include <map>

#include "core/diagnostics.h"
#include "model/yaml_reader.h"
#include "render/scene.h"
#include "gallery/manifest.h"
#include "core/atomic_file.h"
#include "core/image.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

/// A whole non-negative integer, else nullopt.
std::optional<long> wholeNumber(std::string_view text) {
  auto v = parseFiniteNumber(text);
  if (!v || *v < 0 || *v > 1e9 || *v != static_cast<double>(static_cast<long>(*v))) return std::nullopt;
  return static_cast<long>(*v);
}

/// Two FNV-1a 64-bit lanes with different offsets: 128 bits against accidental collisions.
struct Hasher {
  uint64_t a = 0xcbf29ce484222325ull;
  uint64_t b = 0x84222325cbf29ce4ull;
  void bytes(std::string_view s) {
    for (unsigned char c : s) {
      a = (a ^ c) * 0x100000001b3ull;
      b = (b ^ c ^ 0x5a) * 0x100000001b3ull;
    }
  }
  void add(std::string_view s) {
    bytes(s);
    // A length separator so ("ab", "c") and ("a", "bc") differ (appended piecewise: GCC 12
    // warns falsely on "..." + std::string).
    std::string n = "\x1f";
    n += std::to_string(s.size());
    n += "\x1e";
    bytes(n);
  }
  std::string hex() const {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(a),
                  static_cast<unsigned long long>(b));
    return buf;
  }
};

/// Collects string scalars of a YAML tree (keys excluded).
void collectScalars(const YAML::Node& n, std::vector<std::string>& out, int depth = 0) {
  if (depth > 64 || out.size() > 10000) return;
  if (n.IsScalar()) {
    out.push_back(n.Scalar());
  } else if (n.IsSequence()) {
    for (const auto& c : n) collectScalars(c, out, depth + 1);
  } else if (n.IsMap()) {
    for (const auto& kv : n) collectScalars(kv.second, out, depth + 1);
  }
}

std::string qualityName(GalleryQuality q) { return q == GalleryQuality::Final ? "final" : "draft"; }

std::vector<std::string> outputsOf(const GalleryItem& it) {
  std::vector<std::string> o;
  for (const std::string* f : {&it.preview, &it.strip, &it.animation})
    if (!f->empty()) o.push_back(*f);
  return o;
}

bool outputsExist(const fs::path& outDir, const std::vector<std::string>& outputs) {
  std::error_code ec;
  for (const auto& f : outputs)
    if (!fs::is_regular_file(outDir / f, ec)) return false;
  return true;
}

/// Box-filters src into a cw x ch cell at (ox, oy) of sheet, keeping the aspect ratio.
void pasteScaled(const Image& src, Image& sheet, int ox, int oy, int cw, int ch) {
  const double scale = std::min(static_cast<double>(cw) / src.width, static_cast<double>(ch) / src.height);
  const int w = std::max(1, static_cast<int>(src.width * scale)), h = std::max(1, static_cast<int>(src.height * scale));
  const int x0 = ox + (cw - w) / 2, y0 = oy + (ch - h) / 2;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int sx0 = x * src.width / w, sx1 = std::max(sx0 + 1, (x + 1) * src.width / w);
      const int sy0 = y * src.height / h, sy1 = std::max(sy0 + 1, (y + 1) * src.height / h);
      Vec4 sum(0.0f);
      for (int sy = sy0; sy < sy1; ++sy)
        for (int sx = sx0; sx < sx1; ++sx) sum += src.at(sx, sy);
      sheet.set(x0 + x, y0 + y, sum / static_cast<float>((sx1 - sx0) * (sy1 - sy0)));
    }
}

/// The contact sheet: every item's final-stage image in a grid of 240 x 180 cells.
void writeContactSheet(const std::vector<GalleryItem>& items, const fs::path& outDir) {
  constexpr int kCellW = 240, kCellH = 180, kGap = 8;
  std::vector<Image> images;
  for (const auto& it : items)
    if (!it.preview.empty())
      try {
        Image img = readImage(outDir / it.preview);
        for (size_t i = 3; i < img.pixels.size(); i += 4) img.pixels[i] = 1.0f;  // shown opaque
        images.push_back(std::move(img));
      } catch (const ImageReadError&) {
      }
  const int n = std::max<int>(1, static_cast<int>(images.size()));
  const int cols = std::min(6, n), rows = (n + cols - 1) / cols;
  Image sheet(cols * (kCellW + kGap) + kGap, rows * (kCellH + kGap) + kGap, Vec4(0.9f, 0.9f, 0.88f, 1.0f));
  for (size_t i = 0; i < images.size(); ++i) {
    const int c = static_cast<int>(i) % cols, r = static_cast<int>(i) / cols;
    pasteScaled(images[i], sheet, kGap + c * (kCellW + kGap), kGap + r * (kCellH + kGap), kCellW, kCellH);
  }
  writeImage(sheet, outDir / "contact_sheet.png");
}

/// The index's thumbnails: each final stage scaled to fit 320 x 240 (the page's card colour
/// around it), so the index loads a few megabytes, not every full-size picture.
void writeThumbnails(const std::vector<GalleryItem>& items, const fs::path& outDir) {
  constexpr int kThumbW = 320, kThumbH = 240;
  std::error_code ec;
  fs::create_directories(outDir / "thumbs", ec);
  for (const auto& it : items) {
    if (it.preview.empty()) continue;
    try {
      Image img = readImage(outDir / it.preview);
      for (size_t i = 3; i < img.pixels.size(); i += 4) img.pixels[i] = 1.0f;  // shown opaque
      Image thumb(kThumbW, kThumbH, Vec4(0.79f, 0.78f, 0.75f, 1.0f));
      pasteScaled(img, thumb, 0, 0, kThumbW, kThumbH);
      writeImage(thumb, outDir / galleryThumbFile(it));
    } catch (const ImageReadError&) {
    }
  }
}

void writeIndex(std::vector<GalleryItem> items, const fs::path& outDir) {
  std::sort(items.begin(), items.end(), [](const GalleryItem& a, const GalleryItem& b) { return a.source < b.source; });
  writeContactSheet(items, outDir);
  writeThumbnails(items, outDir);
  std::error_code ec;
  fs::create_directories(outDir / "pages", ec);
  for (size_t i = 0; i < items.size(); ++i)
    writeFileAtomic(outDir / galleryPageFile(items[i]), gallerySpeciesPageHtml(items, i));
  writeFileAtomic(outDir / "index.html", galleryIndexHtml(items));
}

}  // namespace

Shard parseShard(std::string_view text) {
  const size_t slash = text.find('/');
  std::optional<long> i, n;
  if (slash != std::string_view::npos) {
    i = wholeNumber(text.substr(0, slash));
    n = wholeNumber(text.substr(slash + 1));
  }
  if (!i || !n || *n < 1 || *i >= *n)
    throw UsageError("--shard " + std::string(text) + ": expected I/N with 0 <= I < N (shard I of N, counted from 0)");
  return {static_cast<int>(*i), static_cast<int>(*n)};
}

std::optional<Shard> shardFromEnvironment(const std::function<const char*(const char*)>& getenv) {
  auto read = [&](const char* name) -> std::optional<long> {
    const char* v = getenv(name);
    if (!v || !*v) return std::nullopt;
    auto n = wholeNumber(v);
    if (!n) throw UsageError(std::string(name) + "=" + v + ": expected a whole number");
    return n;
  };
  auto make = [](long index, long count, const char* what) {
    if (count < 1 || index < 0 || index >= count)
      throw UsageError(std::string(what) + ": shard " + std::to_string(index) + " of " + std::to_string(count) +
                       " is out of range");
    return Shard{static_cast<int>(index), static_cast<int>(count)};
  };
  if (auto id = read("SLURM_ARRAY_TASK_ID")) {
    auto count = read("SLURM_ARRAY_TASK_COUNT");
    if (!count) throw UsageError("SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_COUNT is not");
    // Slurm sets the step for `--array=A-B:S` (a list such as `1,5,9` gets step 1, so only
    // a contiguous list maps onto 0..count-1).
    const long min = read("SLURM_ARRAY_TASK_MIN").value_or(0);
    const long step = read("SLURM_ARRAY_TASK_STEP").value_or(1);
    if (step < 1 || (*id - min) % step != 0)
      throw UsageError("SLURM_ARRAY_TASK_ID=" + std::to_string(*id) + " is not SLURM_ARRAY_TASK_MIN=" +
                       std::to_string(min) + " plus a multiple of SLURM_ARRAY_TASK_STEP=" + std::to_string(step));
    return make((*id - min) / step, *count, "SLURM_ARRAY_TASK_ID");
  }
  if (auto id = read("JOB_COMPLETION_INDEX")) {
    auto count = read("SPRIG_SHARD_COUNT");
    if (!count) throw UsageError("JOB_COMPLETION_INDEX is set but SPRIG_SHARD_COUNT (the job's completions) is not");
    return make(*id, *count, "JOB_COMPLETION_INDEX");
  }
  return std::nullopt;
}

std::vector<size_t> shardItems(const Shard& shard, size_t itemCount) {
  std::vector<size_t> out;
  for (size_t i = static_cast<size_t>(shard.index); i < itemCount; i += static_cast<size_t>(shard.count))
    out.push_back(i);
  return out;
}

/// The running program's own bytes (and its backends library), hashed once: a rebuilt Sprig (a changed renderer, a
/// fixed texture) makes every picture stale, though the version string did not change.
/// Empty when the executable cannot be read; nothing is then up to date.
const std::string& executableHash() {
  static const std::string hash = [] {
    try {
      Hasher h;
      const fs::path exe = fs::read_symlink("/proc/self/exe");
      h.add(readFile(exe));
      // The image and volume code loaded beside it (backends/), when present.
      std::error_code ec;
      const fs::path backends = exe.parent_path() / "libsprig_backends.so";
      if (fs::is_regular_file(backends, ec)) h.add(readFile(backends));
      return h.hex();
    } catch (const std::exception&) {
      return std::string();
    }
  }();
  return hash;
}

std::string galleryInputHash(const fs::path& speciesFile, std::string_view options) {
  Hasher h;
  h.add("sprig " SPRIG_VERSION);
  h.add(executableHash());
  h.add(options);
  std::string text;
  try {
    text = readFile(speciesFile);
  } catch (const std::exception&) {
    h.add("unreadable");
    return h.hex();
  }
  h.add(text);
  // Files the species names (grammar, textures, ...): every string value that is an
  // existing file relative to the species file's folder.
  std::vector<std::string> scalars;
  try {
    collectScalars(YAML::Load(text), scalars);
  } catch (const YAML::Exception&) {
  }
  std::sort(scalars.begin(), scalars.end());
  scalars.erase(std::unique(scalars.begin(), scalars.end()), scalars.end());
  for (const std::string& s : scalars) {
    if (s.empty() || s.size() > 1024 || s.find('\n') != std::string::npos) continue;
    const fs::path p = speciesFile.parent_path() / s;
    std::error_code ec;
    if (!fs::is_regular_file(p, ec)) continue;
    h.add(s);
    try {
      h.add(readFile(p));
    } catch (const std::exception&) {
      h.add("unreadable");
    }
  }
  return h.hex();
}

int removeDeadTemporaries(const fs::path& folder, double minAgeSeconds) {
  int n = 0;
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (auto it = fs::directory_iterator(folder, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(".sprig-tmp-", 0) != 0) continue;
    const long pid = std::strtol(name.c_str() + 11, nullptr, 10);
    if (pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH)) continue;  // owner alive
    std::error_code tec;
    const auto t = fs::last_write_time(it->path(), tec);
    if (minAgeSeconds > 0 && (tec || std::chrono::duration<double>(now - t).count() < minAgeSeconds)) continue;
    std::error_code rec;
    if (fs::remove(it->path(), rec)) ++n;
  }
  return n;
}

GalleryRunResult renderGallery(std::vector<fs::path> files, const fs::path& outDir, const GalleryRunOptions& options,
                               const PathPolicy& policy) {
  std::sort(files.begin(), files.end());
  files.erase(std::unique(files.begin(), files.end()), files.end());
  std::error_code ec;
  fs::create_directories(outDir / "manifests", ec);
  if (!fs::is_directory(outDir / "manifests"))
    throw std::runtime_error(outDir.string() + ": cannot create the gallery folder");
  // Leftovers of killed runs. Shards running beside this one keep theirs: only
  // temporaries of processes that no longer run on this host are removed, and when other
  // shards may be running on other hosts, only those older than ten minutes.
  if (options.shard.count == 1) {
    removeStaleTemporaries(outDir);
    removeStaleTemporaries(outDir / "manifests");
  } else {
    removeDeadTemporaries(outDir, 600);
    removeDeadTemporaries(outDir / "manifests", 600);
  }

  std::map<std::string, ManifestEntry> previous;
  for (Manifest& m : loadManifests(outDir))
    for (ManifestEntry& e : m.entries) previous[e.item.source] = std::move(e);

  const std::string optionText = "gallery-format=2;quality=" + qualityName(options.quality) +
                                 (render::Scene::prunedTapesDefault() ? "" : ";full-tape");
  Manifest manifest;
  manifest.shard = options.shard;
  manifest.quality = qualityName(options.quality);
  GalleryRunResult result;
  for (size_t index : shardItems(options.shard, files.size())) {
    const fs::path& f = files[index];
    const std::string hash = galleryInputHash(f, optionText);
    auto old = previous.find(f.string());
    ManifestEntry entry;
    if (old != previous.end() && !executableHash().empty() && old->second.hash == hash && old->second.item.error.empty() &&
        outputsExist(outDir, old->second.outputs)) {
      entry = old->second;
      ++result.skipped;
      if (!options.quiet) std::cerr << f.string() << ": up to date\n";
    } else {
      entry.item = renderGalleryItem(f, outDir, options.quality, policy);
      entry.hash = hash;
      entry.outputs = outputsOf(entry.item);
      ++result.rendered;
      if (!entry.item.error.empty()) {
        std::cerr << entry.item.error << "\n";
      } else if (!options.quiet) {
        std::cerr << f.string() << ": " << entry.item.modules << " modules, " << entry.item.internodes
                  << " internodes, " << entry.item.frames << " frames, " << entry.item.renderSeconds << " s render (still "
                  << entry.item.stillSeconds << ", strip " << entry.item.stripSeconds << ", animation "
                  << entry.item.animationSeconds << ")\n";
      }
    }
    if (!entry.item.error.empty()) ++result.failed;
    manifest.entries.push_back(std::move(entry));
    writeFileAtomic(manifestPath(outDir, options.shard), manifestJson(manifest));
  }
  if (manifest.entries.empty()) writeFileAtomic(manifestPath(outDir, options.shard), manifestJson(manifest));
  if (options.shard.count == 1) mergeGallery(outDir);
  return result;
}

size_t mergeGallery(const fs::path& outDir) {
  std::vector<Manifest> manifests = loadManifests(outDir);
  if (manifests.empty())
    throw std::runtime_error(outDir.string() + ": no gallery manifests in " + (outDir / "manifests").string());
  std::map<std::string, GalleryItem> items;  // later manifests win
  for (Manifest& m : manifests)
    for (ManifestEntry& e : m.entries) items[e.item.source] = std::move(e.item);
  std::vector<GalleryItem> list;
  for (auto& [source, item] : items) list.push_back(std::move(item));
  writeIndex(std::move(list), outDir);
  return items.size();
}

}  // namespace sprig
