#pragma once
/// Materials of layered solids (Cutler et al., "A procedural approach to authoring solid
/// models", §2.2): rendering and simulation parameters, a built-in library, and procedural
/// materials that choose one of several materials per point.
///
/// Units are SI: density kg/m³, Young's modulus and strength Pa; colours are linear RGB.
/// The built-in values are textbook orders of magnitude (docs/SOLIDS.md lists them), enough
/// for the next issue's simulation operators to tell stiff from soft.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/types.h"
#include "lsystem/expression.h"

namespace sprig::solids {

/// One material. Defaults are those of a material a species file defines without the key.
struct Material {
  std::string name;
  Vec3 color{0.6f};               ///< linear RGB albedo
  float roughness = 0.5f;         ///< render highlight width, 0 = mirror-like, 1 = none
  float specular = 0.04f;         ///< render highlight strength
  double density = 1000;          ///< kg/m³
  double youngsModulus = 1e9;     ///< Pa
  double poissonRatio = 0.3;      ///< dimensionless, in [0, 0.5)
  double strength = 1e7;          ///< tensile strength, Pa (fracture threshold)
};

/// The built-in materials: chocolate, white_chocolate, nut, pink_frosting, foil, bronze,
/// shiny_bronze, fired_clay, stone, dirt, brick, wood (in that order).
const std::vector<Material>& builtinMaterials();

/// The built-in material named name, or null.
const Material* findBuiltinMaterial(const std::string& name);

/// A per-point choice among materials (§2.2's striped chocolate): `select` is an
/// expression of x, y, z whose value, truncated toward zero and clamped to the list,
/// indexes `choices` (ids into a MaterialTable). Thread-safe.
struct ProceduralMaterial {
  std::string name;
  lsystem::Expression select;
  std::vector<int> choices;
  /// The chosen material id at p.
  int at(const DVec3& p) const;
};

/// The materials of one solid: concrete materials by id, and procedural ones that resolve
/// to concrete ids per point. Ids >= 0 are concrete; procedural entries are referenced by
/// -(index + 3) in layers (see Layer::material).
struct MaterialTable {
  std::vector<Material> materials;
  std::vector<ProceduralMaterial> procedural;
  /// Id of the concrete material named name, appending it from the built-ins when needed;
  /// nullopt when unknown.
  std::optional<int> concrete(const std::string& name);
};

}  // namespace sprig::solids
