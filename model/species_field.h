#pragma once
/// A Sprig species as a distance field of a solid (`{species: {file, seed}}`, docs/SOLIDS.md):
/// the species is loaded and meshed as `sprig mesh` does (loadSpecies, SpeciesModel,
/// cleanSurface: the final stage's mesh without its specks and voids), and its closed
/// triangle mesh becomes OpenVDB's signed distance through solids::meshField. This lives in model/ because solids/ knows no
/// species; model/solid_kind.cpp calls it.

#include <cstdint>
#include <memory>
#include <optional>

#include "core/mesh.h"
#include "model/yaml_reader.h"
#include "solids/distance_field.h"

namespace sprig {

/// Most species one top-level species load builds for the species it references (solid
/// `species` fields, organism `species` bases, at any depth). Identical references (the
/// same file, seed and path policy) are built once and shared, so YAML aliases that repeat
/// one reference cost one build; the kMaxSpeciesBuilds + 1-th distinct build is an error
/// at its reference.
inline constexpr int kMaxSpeciesBuilds = 64;

/// Opens the cache and the build count of referenced species for the current thread while
/// it lives, unless one is already open (loadSpecies opens one: nested loads share it).
class SpeciesBuildScope {
 public:
  SpeciesBuildScope();
  ~SpeciesBuildScope();
  SpeciesBuildScope(const SpeciesBuildScope&) = delete;
  SpeciesBuildScope& operator=(const SpeciesBuildScope&) = delete;

 private:
  bool owner_ = false;
};

/// A species referenced from another species, loaded and (unless it is a solid, or a seed
/// was given for a kind other than tree) meshed as `sprig mesh` meshes it.
struct ReferencedSpecies {
  std::string kind;
  bool hasSurface = false;                ///< it has surface settings (a tree needs `tree:`)
  std::shared_ptr<const Mesh> surface;    ///< its cleaned final-stage mesh; null when not built
};

/// The species at `file` (referenced at `at`), from the open scope's cache or built and
/// counted against kMaxSpeciesBuilds (over the limit: an InputError at `at`). A failed load
/// is cached too and throws the same error on every use. seed replaces a tree's seed.
ReferencedSpecies referencedSpecies(const YNode& at, const std::filesystem::path& file, const PathPolicy& policy,
                                    std::optional<uint64_t> seed);

/// Reads the map of a `species` field (keys `file`, `seed`) from m and returns the field,
/// or nullptr after adding diagnostics: at `file` when the file is refused by policy, is a
/// solid species, has no surface, refers back to a file still being read (the cycle is
/// named), or meshes to a surface that is not closed (its first open edge is named); the
/// referred file's own errors keep their file:line:col. `seed` replaces a tree's
/// derivation seed (as `sprig mesh --seed`); other kinds keep theirs, and a seed for them
/// is an error. Does not call m.finish(). Cost: that of meshing the species.
solids::FieldPtr readSpeciesField(MapReader& m, const PathPolicy& policy);

}  // namespace sprig
