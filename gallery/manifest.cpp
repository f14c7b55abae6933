#include "gallery/manifest.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>

#include "core/json_writer.h"
#include "core/atomic_file.h"
#include "core/diagnostics.h"

namespace sprig {

namespace fs = std::filesystem;

namespace {

constexpr int kManifestFormat = 1;

std::string stringList(const std::vector<std::string>& v) {
  std::string o = "[";
  for (size_t i = 0; i < v.size(); ++i) o += (i ? ", " : "") + json::string(v[i]);
  return o + "]";
}

std::string intList(const std::vector<int>& v) {
  std::string o = "[";
  for (size_t i = 0; i < v.size(); ++i) o += (i ? ", " : "") + std::to_string(v[i]);
  return o + "]";
}

}  // namespace

std::string manifestJson(const Manifest& m) {
  std::string o = "{\"sprig\": " + json::string(m.version) + ", \"format\": " + std::to_string(kManifestFormat) +
                  ", \"shard\": " + std::to_string(m.shard.index) + ", \"shards\": " + std::to_string(m.shard.count) +
                  ", \"quality\": " + json::string(m.quality) + ",\n \"items\": [";
  for (size_t i = 0; i < m.entries.size(); ++i) {
    const ManifestEntry& e = m.entries[i];
    const GalleryItem& it = e.item;
    o += i ? ",\n  {" : "\n  {";
    o += "\"source\": " + json::string(it.source) + ", \"hash\": " + json::string(e.hash) +
         ", \"name\": " + json::string(it.name) + ", \"description\": " + json::string(it.description) +
         ", \"kind\": " + json::string(it.kind) + ", \"mode\": " + json::string(it.mode) + ", \"preview\": " + json::string(it.preview) +
         ", \"strip\": " + json::string(it.strip) + ", \"animation\": " + json::string(it.animation) +
         ", \"stages\": " + intList(it.stages) + ", \"modules\": " + std::to_string(it.modules) +
         ", \"internodes\": " + std::to_string(it.internodes) + ", \"primitives\": " + std::to_string(it.primitives) +
         ", \"triangles\": " + std::to_string(it.triangles) + ", \"frames\": " + std::to_string(it.frames) +
         ", \"steps\": " + std::to_string(it.steps) + ", \"derive_seconds\": " + json::number(it.deriveSeconds) +
         ", \"render_seconds\": " + json::number(it.renderSeconds) + ", \"still_seconds\": " + json::number(it.stillSeconds) +
         ", \"strip_seconds\": " + json::number(it.stripSeconds) +
         ", \"animation_seconds\": " + json::number(it.animationSeconds) + ", \"error\": " + json::string(it.error) +
         ", \"outputs\": " + stringList(e.outputs) + "}";
  }
  o += "\n]}\n";
  return o;
}

Manifest parseManifest(const std::string& text, const std::string& displayPath) {
  Manifest m;
  try {
    YAML::Node root = YAML::Load(text);
    if (!root.IsMap()) throw InputError(SourceLoc{displayPath, 1, 1}, "a gallery manifest must be a JSON object");
    if (root["format"].as<int>() != kManifestFormat)
      throw InputError(SourceLoc{displayPath, 1, 1}, "unsupported gallery manifest format");
    m.version = root["sprig"].as<std::string>();
    m.shard.index = root["shard"].as<int>();
    m.shard.count = root["shards"].as<int>();
    m.quality = root["quality"].as<std::string>();
    for (const YAML::Node& n : root["items"]) {
      ManifestEntry e;
      GalleryItem& it = e.item;
      it.source = n["source"].as<std::string>();
      e.hash = n["hash"].as<std::string>();
      it.name = n["name"].as<std::string>();
      it.description = n["description"].as<std::string>();
      it.kind = n["kind"].as<std::string>();
      if (n["mode"]) it.mode = n["mode"].as<std::string>();
      it.preview = n["preview"].as<std::string>();
      it.strip = n["strip"].as<std::string>();
      it.animation = n["animation"].as<std::string>();
      it.stages = n["stages"].as<std::vector<int>>();
      it.modules = n["modules"].as<size_t>();
      it.internodes = n["internodes"].as<size_t>();
      it.primitives = n["primitives"].as<size_t>();
      it.triangles = n["triangles"].as<size_t>();
      it.frames = n["frames"].as<int>();
      it.steps = n["steps"].as<int>();
      it.deriveSeconds = n["derive_seconds"].as<double>();
      it.renderSeconds = n["render_seconds"].as<double>();
      // The parts' times came later: a manifest without them reads as zeros.
      it.stillSeconds = n["still_seconds"] ? n["still_seconds"].as<double>() : 0.0;
      it.stripSeconds = n["strip_seconds"] ? n["strip_seconds"].as<double>() : 0.0;
      it.animationSeconds = n["animation_seconds"] ? n["animation_seconds"].as<double>() : 0.0;
      it.error = n["error"].as<std::string>();
      e.outputs = n["outputs"].as<std::vector<std::string>>();
      m.entries.push_back(std::move(e));
    }
  } catch (const YAML::Exception& e) {
    throw InputError(SourceLoc{displayPath, e.mark.line + 1, e.mark.column + 1},
                     "malformed gallery manifest: " + e.msg);
  }
  return m;
}

fs::path manifestPath(const fs::path& outDir, const Shard& shard) {
  return outDir / "manifests" /
         ("shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".json");
}

std::vector<Manifest> loadManifests(const fs::path& outDir) {
  struct Found {
    fs::file_time_type time;
    fs::path path;
  };
  std::vector<Found> found;
  std::error_code ec;
  for (auto it = fs::directory_iterator(outDir / "manifests", ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    const fs::path& p = it->path();
    if (p.extension() != ".json" || p.filename().string().rfind(".sprig-tmp-", 0) == 0) continue;
    std::error_code tec;
    found.push_back({fs::last_write_time(p, tec), p});
  }
  std::sort(found.begin(), found.end(), [](const Found& a, const Found& b) {
    return a.time != b.time ? a.time < b.time : a.path < b.path;
  });
  std::vector<Manifest> out;
  for (const Found& f : found) {
    try {
      out.push_back(parseManifest(readFile(f.path), f.path.string()));
    } catch (const std::exception&) {
      // A manifest from another Sprig version or a damaged one: its items render again.
    }
  }
  return out;
}

}  // namespace sprig
