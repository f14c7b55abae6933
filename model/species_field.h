#pragma once
/// A Sprig species as a distance field of a solid (`{species: {file, seed}}`, docs/SOLIDS.md):
/// the species is loaded and meshed as `sprig mesh` does (loadSpecies, SpeciesModel,
/// cleanSurface: the final stage's mesh without its specks and voids), and its closed
/// triangle mesh becomes OpenVDB's signed distance through solids::meshField. This lives in model/ because solids/ knows no
/// species; model/solid_kind.cpp calls it.

#include "model/yaml_reader.h"
#include "solids/distance_field.h"

namespace sprig {

/// Reads the map of a `species` field (keys `file`, `seed`) from m and returns the field,
/// or nullptr after adding diagnostics: at `file` when the file is refused by policy, is a
/// solid species, has no surface, refers back to a file still being read (the cycle is
/// named), or meshes to a surface that is not closed (its first open edge is named); the
/// referred file's own errors keep their file:line:col. `seed` replaces a tree's
/// derivation seed (as `sprig mesh --seed`); other kinds keep theirs, and a seed for them
/// is an error. Does not call m.finish(). Cost: that of meshing the species.
solids::FieldPtr readSpeciesField(MapReader& m, const PathPolicy& policy);

}  // namespace sprig
