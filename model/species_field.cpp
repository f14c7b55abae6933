#include "model/species_field.h"

#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/mesh.h"
#include "core/polymesh.h"
#include "model/kind_name.h"
#include "model/model.h"
#include "model/species.h"

namespace sprig {

namespace {

/// The species files being read on this thread, outermost first: a file that appears here
/// again is a cycle.
thread_local std::vector<std::filesystem::path> gOpenFiles;

std::filesystem::path identity(const std::filesystem::path& p) {
  std::error_code ec;
  std::filesystem::path c = std::filesystem::weakly_canonical(p, ec);
  return ec ? p.lexically_normal() : c;
}

/// Pushes a file on gOpenFiles for a scope.
struct OpenFile {
  explicit OpenFile(std::filesystem::path p) { gOpenFiles.push_back(std::move(p)); }
  ~OpenFile() { gOpenFiles.pop_back(); }
  OpenFile(const OpenFile&) = delete;
  OpenFile& operator=(const OpenFile&) = delete;
};

/// mesh with vertices at the same position made one, as a polygon mesh (the polygonizer's
/// and the kinds' meshes may repeat a vertex per face; a distance field needs the topology).
PolyMesh welded(const Mesh& mesh) {
  PolyMesh out;
  std::map<std::array<uint32_t, 3>, uint32_t> index;
  std::vector<uint32_t> remap(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    std::array<uint32_t, 3> key;
    std::memcpy(key.data(), &mesh.positions[i], sizeof key);
    auto [it, fresh] = index.try_emplace(key, uint32_t(out.positions.size()));
    if (fresh) out.positions.push_back(mesh.positions[i]);
    remap[i] = it->second;
  }
  for (const glm::uvec3& t : mesh.triangles) {
    const uint32_t a = remap[t.x], b = remap[t.y], c = remap[t.z];
    if (a == b || b == c || a == c) continue;  // collapsed by welding
    out.faceSizes.push_back(3);
    out.faceVertices.insert(out.faceVertices.end(), {a, b, c});
  }
  return out;
}

/// One cached build: its result, or the error it threw.
struct CachedBuild {
  ReferencedSpecies species;
  std::optional<InputError> inputError;
  std::string otherError;  ///< what() of any other exception
};

/// The cache and the build count of the open SpeciesBuildScope.
struct BuildCache {
  std::map<std::string, CachedBuild> builds;  // key: file identity, root, allowOutside, seed
  std::map<const Mesh*, solids::FieldPtr> fields;  // the distance field of a cached surface
  int count = 0;
};

thread_local BuildCache* gBuildCache = nullptr;

CachedBuild build(const std::filesystem::path& file, const PathPolicy& policy, std::optional<uint64_t> seed) {
  CachedBuild out;
  try {
    const Species species = loadSpecies(file, policy);
    out.species.kind = species.kind;
    if (species.kind == "solid" || (seed && species.kind != "tree")) return out;
    ModelOptions options;
    if (seed) options.extra.seed = *seed;
    SpeciesModel model(species, options);
    out.species.hasSurface = model.hasSurfaceSettings();
    // Cleaned as `sprig mesh` cleans it: a speck beside the surface or a void inside it
    // would otherwise be a separate piece (of a solid, of an organism).
    if (out.species.hasSurface) out.species.surface = std::make_shared<const Mesh>(model.cleanSurface());
  } catch (const InputError& e) {
    out.inputError = e;
  } catch (const std::exception& e) {
    out.otherError = e.what();
  }
  return out;
}

}  // namespace

SpeciesBuildScope::SpeciesBuildScope() {
  if (gBuildCache) return;
  gBuildCache = new BuildCache;
  owner_ = true;
}

SpeciesBuildScope::~SpeciesBuildScope() {
  if (!owner_) return;
  delete gBuildCache;
  gBuildCache = nullptr;
}

ReferencedSpecies referencedSpecies(const YNode& at, const std::filesystem::path& file, const PathPolicy& policy,
                                    std::optional<uint64_t> seed) {
  SpeciesBuildScope scope;  // a caller outside loadSpecies (a test) gets a scope of its own
  BuildCache& cache = *gBuildCache;
  const std::string key = identity(file).string() + '\n' + identity(std::filesystem::absolute(policy.root)).string() + '\n' +
                          (policy.allowOutside ? "1" : "0") + '\n' + (seed ? std::to_string(*seed) : "-");
  auto it = cache.builds.find(key);
  if (it == cache.builds.end()) {
    if (cache.count >= kMaxSpeciesBuilds)
      throw InputError(at.loc(), "more than " + std::to_string(kMaxSpeciesBuilds) +
                                     " different species referenced by one species (kMaxSpeciesBuilds); identical references are built once",
                       at.file().sourceLine(at.loc().line));
    ++cache.count;
    it = cache.builds.emplace(key, build(file, policy, seed)).first;
  }
  const CachedBuild& b = it->second;
  if (b.inputError) throw *b.inputError;
  if (!b.otherError.empty()) throw std::runtime_error(b.otherError);
  return b.species;
}

solids::FieldPtr readSpeciesField(MapReader& m, const PathPolicy& policy) {
  DiagnosticList& diags = m.diagnostics();
  std::optional<int64_t> seed;
  if (m.has("seed")) seed = m.integer({"seed", "Trees only: replaces the derivation seed, as `sprig mesh --seed` (default: the tree's own)."}, 0, 0);
  m.markRequired("file");
  auto file = m.path({"file", "A blob, shell, tree or organism species file, relative to this one; required."}, policy);
  if (!file) {
    if (!m.has("file")) m.node().error(diags, "missing required key 'file' in species (a blob, shell, tree or organism species file)");
    return nullptr;
  }
  const YNode at = *m.get("file");
  const std::string name = sprig::quoted(file->string());

  // A cycle: the referred file is the referring one or one still being read around it.
  const std::filesystem::path self = identity(at.file().path());
  const std::filesystem::path target = identity(*file);
  std::vector<std::filesystem::path> chain = gOpenFiles;
  if (chain.empty() || chain.back() != self) chain.push_back(self);
  for (size_t i = 0; i < chain.size(); ++i)
    if (chain[i] == target) {
      std::string text;
      for (size_t k = i; k < chain.size(); ++k) text += chain[k].filename().string() + " -> ";
      text += target.filename().string();
      at.error(diags, "species files refer to each other in a cycle: " + text + " (a species field cannot contain itself)");
      return nullptr;
    }

  const bool outer = gOpenFiles.empty();
  std::optional<OpenFile> selfOpen;
  if (outer || gOpenFiles.back() != self) selfOpen.emplace(self);
  OpenFile targetOpen(target);
  try {
    const ReferencedSpecies species =
        referencedSpecies(at, *file, policy, seed ? std::optional<uint64_t>(uint64_t(*seed)) : std::nullopt);
    if (species.kind == "solid") {
      at.error(diags, name + " is a solid species, and a solid species is not a distance field (name a blob, shell, tree or organism species)");
      return nullptr;
    }
    if (seed && species.kind != "tree") {
      m.get("seed")->error(diags, "'seed' replaces a tree's derivation seed; " + name + " is " + speciesOfKind(species.kind) +
                                      " (its seeds are in its own file)");
      return nullptr;
    }
    if (!species.hasSurface) {
      at.error(diags, "species " + name + " has no surface (a tree needs a tree: section)");
      return nullptr;
    }
    if (gBuildCache) {  // the same surface referenced again: its field too is made once
      auto known = gBuildCache->fields.find(species.surface.get());
      if (known != gBuildCache->fields.end()) return known->second;
    }
    const PolyMesh mesh = welded(*species.surface);
    if (mesh.faceSizes.empty()) {
      at.error(diags, "the surface of species " + name + " is empty");
      return nullptr;
    }
    if (auto open = solids::firstOpenEdge(mesh)) {
      const Vec3 p = mesh.positions[open->a], q = mesh.positions[open->b];
      char where[160];
      std::snprintf(where, sizeof where, " (from %.4g, %.4g, %.4g to %.4g, %.4g, %.4g)", p.x, p.y, p.z, q.x, q.y, q.z);
      at.error(diags, "the surface of species " + name + " is not closed: the edge from vertex " + std::to_string(open->a + 1) +
                          " to vertex " + std::to_string(open->b + 1) + where +
                          " has only one face (a distance field needs a closed mesh)");
      return nullptr;
    }
    solids::FieldPtr field = solids::meshField(mesh);
    if (gBuildCache) gBuildCache->fields[species.surface.get()] = field;
    return field;
  } catch (const InputError& e) {
    diags.append(e.diagnostics());
  } catch (const std::exception& e) {
    at.error(diags, e.what());
  }
  return nullptr;
}

}  // namespace sprig
