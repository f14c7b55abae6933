#include "solids/material.h"

#include <algorithm>
#include <cmath>

#include "core/srgb.h"

namespace sprig::solids {

namespace {

Material make(const char* name, Vec3 srgb, float roughness, float specular, double density, double young,
              double poisson, double strength) {
  Material m;
  m.name = name;
  m.color = Vec3(srgbToLinear(srgb.x), srgbToLinear(srgb.y), srgbToLinear(srgb.z));
  m.roughness = roughness;
  m.specular = specular;
  m.density = density;
  m.youngsModulus = young;
  m.poissonRatio = poisson;
  m.strength = strength;
  return m;
}

}  // namespace

const std::vector<Material>& builtinMaterials() {
  // Colours are sRGB here (chocolate is the paper's { 0.31 0.17 0.15 }); physics after
  // common references: confectionery literature for chocolate and frosting, engineering
  // tables for metals, ceramics, stone and wood.
  static const std::vector<Material> kMaterials = {
      make("chocolate", {0.31f, 0.17f, 0.15f}, 0.45f, 0.06f, 1100, 5e8, 0.35, 2e6),
      make("white_chocolate", {0.93f, 0.87f, 0.74f}, 0.45f, 0.06f, 1100, 3e8, 0.35, 1.5e6),
      make("nut", {0.72f, 0.50f, 0.30f}, 0.6f, 0.03f, 1000, 5e7, 0.3, 5e6),
      make("pink_frosting", {0.95f, 0.60f, 0.70f}, 0.5f, 0.05f, 900, 1e6, 0.45, 5e4),
      make("foil", {0.70f, 0.71f, 0.75f}, 0.2f, 0.6f, 2700, 6.9e10, 0.33, 9e7),
      make("bronze", {0.55f, 0.37f, 0.17f}, 0.5f, 0.15f, 8800, 1.1e11, 0.34, 3.5e8),
      make("shiny_bronze", {0.80f, 0.55f, 0.25f}, 0.12f, 0.6f, 8800, 1.1e11, 0.34, 3.5e8),
      make("fired_clay", {0.70f, 0.38f, 0.24f}, 0.8f, 0.02f, 1900, 1.5e10, 0.2, 5e6),
      make("stone", {0.78f, 0.76f, 0.72f}, 0.8f, 0.03f, 2600, 5e10, 0.25, 5e6),
      make("dirt", {0.36f, 0.26f, 0.17f}, 0.9f, 0.01f, 1600, 3e7, 0.35, 3e4),
      make("brick", {0.60f, 0.22f, 0.15f}, 0.85f, 0.02f, 1900, 1.5e10, 0.2, 3e6),
      make("wood", {0.55f, 0.38f, 0.22f}, 0.7f, 0.04f, 600, 1e10, 0.35, 4e7),
  };
  return kMaterials;
}

const Material* findBuiltinMaterial(const std::string& name) {
  for (const Material& m : builtinMaterials())
    if (m.name == name) return &m;
  return nullptr;
}

int ProceduralMaterial::at(const DVec3& p) const {
  const double v = select({p.x, p.y, p.z});
  const double i = std::isfinite(v) ? std::trunc(v) : 0.0;
  return choices[size_t(std::clamp(i, 0.0, double(choices.size() - 1)))];
}

std::optional<int> MaterialTable::concrete(const std::string& name) {
  for (size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == name) return int(i);
  if (const Material* b = findBuiltinMaterial(name)) {
    materials.push_back(*b);
    return int(materials.size() - 1);
  }
  return std::nullopt;
}

}  // namespace sprig::solids
