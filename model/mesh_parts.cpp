#include "model/mesh_parts.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "core/parallel.h"

namespace sprig {

blobtree::PolygonizeOptions polygonizeOptions(const SpeciesRender& look) {
  blobtree::PolygonizeOptions po;
  po.mesher = look.dualMesher ? blobtree::PolygonizeOptions::Mesher::DualMarchingCubes
                              : blobtree::PolygonizeOptions::Mesher::MarchingTetrahedra;
  return po;
}

Mesh paintPolygonized(const blobtree::PolygonizeResult& result, const render::TextureTable& textures, const Vec3& base) {
  render::Material material;
  material.baseColor = base;
  return paintPolygonized(result, textures, material);
}

Mesh paintPolygonized(const blobtree::PolygonizeResult& result, const render::TextureTable& textures,
                      const render::Material& material) {
  const Vec3 base = material.baseColor;
  Mesh mesh = result.mesh;
  const size_t n = mesh.positions.size();
  if (result.attributes.size() != n) throw std::invalid_argument("paintPolygonized: the mesh has no attributes");
  mesh.colors.assign(n, base);
  for (size_t v = 0; v < n; ++v) {
    const blobtree::Attributes& a = result.attributes[v];
    if (a.textureCount == 0 || textures.empty()) continue;
    Vec3 sum(0);
    float wsum = 0;
    if (material.textureLayers) {
      for (int i = 0; i < a.layerCount && i < blobtree::Attributes::kMaxLayers; ++i) {
        const blobtree::Attributes::Layer& l = a.layers[size_t(i)];
        if (!(l.weight > 0)) continue;
        sum += l.weight * (l.textureId < textures.size() ? textures[l.textureId](l.uv, mesh.positions[v]) : base);
        wsum += l.weight;
      }
    } else {
      for (int i = 0; i < a.textureCount && i < blobtree::Attributes::kMaxTextures; ++i) {
        const float w = a.textureWeights[size_t(i)];
        if (!(w > 0)) continue;
        const uint16_t id = a.textureIds[size_t(i)];
        sum += w * (id < textures.size() ? textures[id](a.uv, mesh.positions[v]) : base);
        wsum += w;
      }
    }
    if (wsum > 0) mesh.colors[v] = sum / wsum * static_cast<float>(1.0 - material.ridge.darkness(a.contact, mesh.positions[v]));
  }
  mesh.materials.assign(mesh.triangles.size(), kNoPartTexture);
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    std::map<uint32_t, float> weight;
    for (int k = 0; k < 3; ++k) {
      const blobtree::Attributes& a = result.attributes[mesh.triangles[t][k]];
      for (int i = 0; i < a.textureCount && i < blobtree::Attributes::kMaxTextures; ++i)
        weight[a.textureIds[size_t(i)]] += a.textureWeights[size_t(i)];
    }
    float best = 0;
    for (const auto& [id, w] : weight)  // ties go to the smaller id (map order)
      if (w > best) best = w, mesh.materials[t] = id;
  }
  return mesh;
}

std::shared_ptr<PartTexture> bakeTexture(int width, int height, const std::function<Vec3(double s, double t)>& colorAt,
                                         const UvSeamOptions& seams) {
  auto tex = std::make_shared<PartTexture>();
  tex->seams = seams;
  tex->image = Image(width, height, Vec4(0, 0, 0, 1));
  Image& im = tex->image;
  parallelFor(0, size_t(height), [&](size_t y) {
    const double t = 1.0 - (double(y) + 0.5) / height;  // top row = t near 1
    for (int x = 0; x < width; ++x) {
      const Vec3 c = colorAt((x + 0.5) / width, t);
      im.set(x, int(y), Vec4(c, 1.0f));
    }
  });
  return tex;
}

void textureBark(ExportPart& part, const std::function<Vec3(Vec2 uv)>& bark) {
  Mesh& mesh = part.mesh;
  if (mesh.uvs.size() != mesh.positions.size() || mesh.uvs.empty())
    throw std::invalid_argument("textureBark: the wood mesh has no texture coordinates");
  float lo = INFINITY, hi = -INFINITY;
  for (const Vec2& uv : mesh.uvs)
    if (std::isfinite(uv.y)) lo = std::min(lo, uv.y), hi = std::max(hi, uv.y);
  if (!(hi >= lo)) lo = 0, hi = 1;
  const float range = std::max(hi - lo, 1e-6f);
  for (Vec2& uv : mesh.uvs) uv.y = std::isfinite(uv.y) ? (uv.y - lo) / range : 0.0f;
  UvSeamOptions seams;
  seams.repeatU = true;
  part.material.texture = bakeTexture(kExportTextureShort, kExportTextureLong, [&](double s, double t) {
    return bark(Vec2(float(s), float(lo + t * range)));
  }, seams);
}

std::vector<std::pair<uint32_t, Mesh>> splitByMaterial(const Mesh& mesh) {
  if (mesh.materials.size() != mesh.triangles.size())
    throw std::invalid_argument("splitByMaterial: the mesh has no per-triangle ids");
  std::map<uint32_t, std::vector<size_t>> groups;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) groups[mesh.materials[t]].push_back(t);
  std::vector<std::pair<uint32_t, Mesh>> out;
  const size_t n = mesh.positions.size();
  for (const auto& [id, tris] : groups) {
    std::vector<uint32_t> remap(n, UINT32_MAX);
    for (size_t t : tris)
      for (int k = 0; k < 3; ++k) remap[mesh.triangles[t][k]] = 0;
    Mesh part;
    uint32_t next = 0;
    for (size_t v = 0; v < n; ++v) {
      if (remap[v] == UINT32_MAX) continue;
      remap[v] = next++;
      part.positions.push_back(mesh.positions[v]);
      if (mesh.normals.size() == n) part.normals.push_back(mesh.normals[v]);
      if (mesh.uvs.size() == n) part.uvs.push_back(mesh.uvs[v]);
      if (mesh.colors.size() == n) part.colors.push_back(mesh.colors[v]);
    }
    for (size_t t : tris) {
      const glm::uvec3& tri = mesh.triangles[t];
      part.triangles.push_back(glm::uvec3(remap[tri.x], remap[tri.y], remap[tri.z]));
    }
    out.emplace_back(id, std::move(part));
  }
  return out;
}

blobtree::PolygonizeResult polygonizeForLook(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options,
                                             const SpeciesRender& look) {
  blobtree::PolygonizeResult r = blobtree::polygonizeDetailed(blob, options);
  if (!(look.simplify > 0) || r.mesh.triangles.empty()) return r;
  std::vector<uint32_t> source;
  r.mesh = organisms::simplifyToError(r.mesh, float(look.simplify), nullptr, &source);
  if (!r.attributes.empty()) {
    std::vector<blobtree::Attributes> kept(source.size());
    for (size_t v = 0; v < source.size(); ++v) kept[v] = r.attributes[source[v]];
    r.attributes = std::move(kept);
  }
  return r;
}

std::vector<organisms::SimplifyReport> simplifyParts(std::vector<ExportPart>& parts, double relativeError) {
  auto extent = [](const Box3& b) { return b.empty() ? 0.0f : std::max({b.size().x, b.size().y, b.size().z}); };
  Box3 all;
  for (const ExportPart& p : parts)
    if (!p.mesh.triangles.empty()) all.extend(p.mesh.bounds());
  const double absolute = relativeError * double(extent(all));
  std::vector<organisms::SimplifyReport> reports(parts.size());
  for (size_t i = 0; i < parts.size(); ++i) {
    Mesh& m = parts[i].mesh;
    const float own = extent(m.bounds());
    if (m.triangles.empty() || !(own > 0)) continue;
    m = organisms::simplifyToError(m, float(absolute / double(own)), &reports[i]);
  }
  return reports;
}

}  // namespace sprig
