#include "model/detail_maps.h"

#include <cmath>

#include "core/mesh_corners.h"
#include "core/parallel.h"
#include "model/mesh_parts.h"

namespace sprig {

namespace {

// full with only what a hit reads: positions, triangles, normals and (colors) colours.
Mesh hitMesh(const Mesh& full, bool colors) {
  Mesh m;
  m.positions = full.positions;
  m.triangles = full.triangles;
  if (full.normals.size() == full.positions.size()) m.normals = full.normals;
  if (colors && full.colors.size() == full.positions.size()) m.colors = full.colors;
  return m;
}

}  // namespace

DetailSurface::DetailSurface(const Mesh& full, const Vec3& baseColor, bool colors) : triangles_(full.triangles.size()) {
  render::Material material;
  material.baseColor = baseColor;
  scene_.addMesh(hitMesh(full, colors), scene_.addMaterial(material));
  scene_.commit();
}

std::optional<render::SurfaceHit> DetailSurface::nearest(const Vec3& p, const Vec3& normal, float maxDistance) const {
  std::optional<render::SurfaceHit> best;
  for (const float side : {1.0f, -1.0f}) {
    // The second ray need not reach beyond the first one's hit: only a nearer hit counts.
    std::optional<render::SurfaceHit> h = scene_.intersect(p, side * normal, 0.0f, best ? best->t : maxDistance);
    if (h && glm::dot(h->normal, normal) > 0.0f && (!best || h->t < best->t)) best = h;
  }
  return best;
}

Vec3 encodeTangentNormal(const Vec3& n) {
  Vec3 out;
  for (int k = 0; k < 3; ++k) out[k] = (128.0f + std::round(127.0f * std::clamp(n[k], -1.0f, 1.0f))) / 255.0f;
  return out;
}

DetailMaps bakeDetailMaps(const Mesh& low, const Vec3& baseColor, const DetailSurface& full, float maxDistance, bool colors) {
  DetailMaps maps;
  if (low.normals.size() != low.positions.size() || low.triangles.empty()) return maps;
  const CreaseNormals corners = splitCreaseNormals(low);
  const bool lowColors = low.colors.size() == low.positions.size();
  const AtlasLayout layout = atlasLayout(low.triangles.size());
  if (layout.cell == 0) return maps;
  // The atlas' uv mapping of every triangle is the same right triangle (bakeAtlas): corner 1
  // along +s, corner 2 along +t.
  const Vec2 uv[3] = {Vec2(0.0f), Vec2(1.0f, 0.0f), Vec2(0.0f, 1.0f)};
  std::vector<size_t> hits(low.triangles.size(), 0);
  // Each corner's unit normal and tangent, once per corner rather than once per texel.
  std::vector<Vec3> cornerNormal(low.triangles.size() * 3);
  std::vector<glm::vec4> cornerTangents(low.triangles.size() * 3);
  parallelFor(0, low.triangles.size(), [&](size_t t) {
    const glm::uvec3& tri = low.triangles[t];
    const Vec3 P[3] = {low.positions[tri.x], low.positions[tri.y], low.positions[tri.z]};
    for (size_t k = 0; k < 3; ++k) {
      const Vec3 nk = corners.normals.values[corners.normals.index[t * 3 + k]];
      cornerNormal[t * 3 + k] = glm::normalize(nk);
      cornerTangents[t * 3 + k] = cornerTangent(P, uv, nk);
    }
  });
  auto texel = [&](size_t t, const Vec3& p, const Vec3& b, Vec3* out) {
    const glm::uvec3& tri = low.triangles[t];
    Vec3 n(0.0f), tangent(0.0f);
    float w = 0.0f;
    for (int k = 0; k < 3; ++k) {
      const glm::vec4& tk = cornerTangents[t * 3 + size_t(k)];
      n += b[k] * cornerNormal[t * 3 + size_t(k)];
      tangent += b[k] * Vec3(tk);
      w += b[k] * tk.w;
    }
    n = glm::normalize(n);
    tangent = glm::normalize(tangent - n * glm::dot(n, tangent));
    const Vec3 bitangent = glm::cross(n, tangent) * (w < 0.0f ? -1.0f : 1.0f);
    const std::optional<render::SurfaceHit> hit = full.nearest(p, n, maxDistance);
    Vec3 tn(0, 0, 1);
    if (hit) {
      tn = Vec3(glm::dot(hit->normal, tangent), glm::dot(hit->normal, bitangent), glm::dot(hit->normal, n));
      const float len = glm::length(tn);
      tn = len > 0.0f ? tn / len : Vec3(0, 0, 1);
      ++hits[t];
    }
    out[0] = encodeTangentNormal(tn);
    if (colors)
      out[1] = hit ? hit->color
               : lowColors ? b.x * low.colors[tri.x] + b.y * low.colors[tri.y] + b.z * low.colors[tri.z]
                           : baseColor;
  };
  // 8-bit, as the glb stores them: the normal map's bytes 128 + round(127·nᵢ), the colours' sRGB.
  std::vector<ImageEncoding> eightBit{ImageEncoding::Data};
  if (colors) eightBit.push_back(ImageEncoding::TextureMap);
  std::vector<std::shared_ptr<PartTexture>> images = bakeAtlases(low, colors ? 2 : 1, texel, true, eightBit);
  if (images.empty()) return maps;
  maps.normal = images[0];
  if (colors) maps.color = images[1];
  const size_t leg = size_t(layout.cell - 3);
  maps.texels = low.triangles.size() * (leg + 1) * (leg + 2) / 2;  // the texels inside the triangles
  for (size_t h : hits) maps.hits += h;
  return maps;
}

}  // namespace sprig
