#include "model/mesh_parts.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

#include "core/mesh_clean.h"
#include "core/parallel.h"

namespace sprig {

blobtree::PolygonizeOptions polygonizeOptions(const SpeciesRender& look) {
  blobtree::PolygonizeOptions po;
  po.mesher = look.dualMesher ? blobtree::PolygonizeOptions::Mesher::DualMarchingCubes
                              : blobtree::PolygonizeOptions::Mesher::MarchingTetrahedra;
  po.vertexData = blobtree::PolygonizeOptions::VertexData::Blend;  // painted as the renderer paints
  return po;
}

float lodCellSize(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options, size_t triangles,
                  bool keepLimbs) {
  if (options.cellSize > 0.0f) return options.cellSize;
  const float fine = blobtree::resolveCellSize(blob, options);
  if (!(fine > 0.0f) || triangles == 0 || !(lodCellCeiling(blob, options, fine, keepLimbs) > fine)) return fine;
  blobtree::PolygonizeOptions probe = options;
  probe.cellSize = fine * kLodProbeCells;
  probe.refineSteps = 0;  // the triangles follow the grid's signs alone
  probe.normals = probe.progress = false;
  probe.vertexData = blobtree::PolygonizeOptions::VertexData::None;
  const double counted = double(blobtree::polygonizeDetailed(blob, probe).mesh.triangles.size());
  if (!(counted > 0.0)) return fine;
  const double cell = double(probe.cellSize) * std::sqrt(counted / double(triangles));
  return float(std::clamp(cell, double(fine), double(lodCellCeiling(blob, options, fine, keepLimbs))));
}

float lodCellCeiling(const blobtree::CompiledBlob& blob, const blobtree::PolygonizeOptions& options, float fine,
                     bool keepLimbs) {
  const float probe = fine * kLodProbeCells;
  if (!keepLimbs) return probe;
  const float limb = options.limbFraction * blob.thinnestLimb();
  // Limbs that the automatic cell keeps whole stay whole; thinner ones break there already.
  return options.limbFraction > 0.0f && limb >= fine ? std::min(probe, limb) : probe;
}

Mesh paintPolygonized(const blobtree::PolygonizeResult& result, const render::TextureTable& textures, const Vec3& base) {
  render::Material material;
  material.baseColor = base;
  return paintPolygonized(result, textures, material);
}

Vec3 paintedColor(const blobtree::Attributes& a, const Vec3& p, const render::TextureTable& textures,
                  const render::Material& material) {
  return render::blendedColor(a, p, material, textures.data(), textures.size());
}

Mesh paintPolygonized(const blobtree::PolygonizeResult& result, const render::TextureTable& textures,
                      const render::Material& material) {
  Mesh mesh = result.mesh;
  const size_t n = mesh.positions.size();
  if (result.attributes.size() != n) throw std::invalid_argument("paintPolygonized: the mesh has no attributes");
  mesh.colors.resize(n);
  for (size_t v = 0; v < n; ++v) mesh.colors[v] = paintedColor(result.attributes[v], mesh.positions[v], textures, material);
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

AtlasLayout atlasLayout(size_t triangles) {
  AtlasLayout l;
  if (triangles == 0) return l;
  const size_t columns = size_t(std::ceil(std::sqrt(double(triangles))));
  const int cell = std::min<int>(kAtlasMaxCell, int(size_t(kAtlasMaxSize) / columns));
  if (cell < kAtlasMinCell) return l;
  l.cell = cell;
  l.columns = int(columns);
  l.rows = int((triangles + columns - 1) / columns);
  return l;
}

namespace {

// Barycentric coordinates (of corners 1 and 2) of a point of the unit right triangle's
// plane, clamped to the triangle (the nearest point of the triangle in that plane).
Vec3 clampedBary(double l1, double l2) {
  l1 = std::max(l1, 0.0), l2 = std::max(l2, 0.0);
  if (l1 + l2 > 1) {
    const double d = (l1 + l2 - 1) / 2;  // onto the hypotenuse along its normal
    l1 -= d, l2 -= d;
    if (l1 < 0) l2 = 1, l1 = 0;
    if (l2 < 0) l1 = 1, l2 = 0;
  }
  return Vec3(float(1 - l1 - l2), float(l1), float(l2));
}

bool ownColors(const ExportPart& part) {
  const Mesh& m = part.mesh;
  if (m.colors.size() != m.positions.size() || m.triangles.empty()) return false;
  for (const Vec3& c : m.colors)
    if (glm::any(glm::greaterThan(glm::abs(c - part.material.baseColor), Vec3(1e-6f)))) return true;
  return false;
}

}  // namespace

std::vector<std::shared_ptr<PartTexture>> bakeAtlases(const Mesh& mesh, int count, const SurfaceTexel& texelAt,
                                                      bool gutterCopies, const std::vector<ImageEncoding>& eightBit) {
  const AtlasLayout l = atlasLayout(mesh.triangles.size());
  if (l.cell == 0 || count < 1 || count > kMaxAtlases || (!eightBit.empty() && eightBit.size() != size_t(count))) return {};
  const int W = l.width(), H = l.height(), c = l.cell;
  const size_t nt = mesh.triangles.size();
  std::vector<std::shared_ptr<PartTexture>> out;
  for (int k = 0; k < count; ++k) {
    auto tex = std::make_shared<PartTexture>();
    if (eightBit.empty())
      tex->image = Image(W, H, Vec4(0, 0, 0, 1));
    else
      tex->image8 = Image8(W, H, eightBit[size_t(k)] == ImageEncoding::Picture ? 4 : 3, eightBit[size_t(k)]);
    tex->atlasCell = c;
    tex->atlas.values.resize(nt * 3);
    tex->atlas.index.resize(nt * 3);
    out.push_back(std::move(tex));
  }
  // Corners on texel centres: a lookup at a corner reads that texel alone, the colour
  // there (texels at corners would average four, up to a quarter of a 4-texel patch apart).
  const Vec2 corner[3] = {Vec2(1.5f, 1.5f), Vec2(float(c) - 1.5f, 1.5f), Vec2(1.5f, float(c) - 1.5f)};
  parallelFor(0, nt, [&](size_t t) {
    const int x0 = int(t % size_t(l.columns)) * c, y0 = int(t / size_t(l.columns)) * c;  // texels from bottom-left
    const glm::uvec3& tri = mesh.triangles[t];
    const Vec3 P[3] = {mesh.positions[tri.x], mesh.positions[tri.y], mesh.positions[tri.z]};
    for (const std::shared_ptr<PartTexture>& tex : out)
      for (int k = 0; k < 3; ++k) {
        tex->atlas.index[t * 3 + size_t(k)] = uint32_t(t * 3 + size_t(k));
        tex->atlas.values[t * 3 + size_t(k)] = Vec2((float(x0) + corner[k].x) / float(W), (float(y0) + corner[k].y) / float(H));
      }
    // The patch's values first (patch[(j·c + i)·kMaxAtlases + k]), then stored at once: an
    // 8-bit image quantizes each value at its own texel, as the float image's writer would.
    std::array<Vec3, size_t(kAtlasMaxCell * kAtlasMaxCell * kMaxAtlases)> patch;
    const auto at = [&](int i, int j) { return &patch[size_t(j * c + i) * kMaxAtlases]; };
    const int leg = c - 3;  // texel (i, j) has barycentric (i − 1, j − 1)/leg
    auto bake = [&](int i, int j) {
      const Vec3 b = clampedBary(double(i - 1) / leg, double(j - 1) / leg);
      texelAt(t, b.x * P[0] + b.y * P[1] + b.z * P[2], b, at(i, j));
    };
    auto inside = [leg](int i, int j) { return i >= 1 && j >= 1 && i + j - 2 <= leg; };
    for (int j = 0; j < c; ++j)
      for (int i = 0; i < c; ++i)
        if (!gutterCopies || inside(i, j)) bake(i, j);
    // Gutter texels: the inside texel nearest to the texel's point clamped to the triangle.
    for (int j = 0; gutterCopies && j < c; ++j)
      for (int i = 0; i < c; ++i) {
        if (inside(i, j)) continue;
        const Vec3 b = clampedBary(double(i - 1) / leg, double(j - 1) / leg);
        int si = 1 + int(std::lround(double(b.y) * leg)), sj = 1 + int(std::lround(double(b.z) * leg));
        while (!inside(si, sj)) (si > sj ? si : sj) -= 1;
        std::copy(at(si, sj), at(si, sj) + count, at(i, j));
      }
    for (int j = 0; j < c; ++j)
      for (int i = 0; i < c; ++i)
        for (size_t k = 0; k < out.size(); ++k) {
          const int x = x0 + i, y = H - 1 - (y0 + j);
          if (eightBit.empty())
            out[k]->image.set(x, y, Vec4(at(i, j)[k], 1.0f));
          else
            out[k]->image8.set(x, y, at(i, j)[k]);
        }
  });
  return out;
}

std::shared_ptr<PartTexture> bakeAtlas(const Mesh& mesh, const SurfaceColor& colorAt) {
  auto one = bakeAtlases(mesh, 1, [&colorAt](size_t t, const Vec3& p, const Vec3& b, Vec3* out) { out[0] = colorAt(t, p, b); });
  return one.empty() ? nullptr : one[0];
}

std::shared_ptr<PartTexture> deferAtlas(std::shared_ptr<const Mesh> mesh, SurfaceColor colorAt) {
  const AtlasLayout l = atlasLayout(mesh->triangles.size());
  if (l.cell == 0) return nullptr;
  // The corners of bakeAtlas now (texel centres (1.5, 1.5), (c − 1.5, 1.5), (1.5, c − 1.5)
  // of each patch), its image on first use.
  auto tex = std::make_shared<PartTexture>();
  const int W = l.width(), H = l.height(), c = l.cell;
  const Vec2 corner[3] = {Vec2(1.5f, 1.5f), Vec2(float(c) - 1.5f, 1.5f), Vec2(1.5f, float(c) - 1.5f)};
  const size_t nt = mesh->triangles.size();
  tex->atlasCell = c;
  tex->atlas.values.resize(nt * 3);
  tex->atlas.index.resize(nt * 3);
  for (size_t t = 0; t < nt; ++t) {
    const int x0 = int(t % size_t(l.columns)) * c, y0 = int(t / size_t(l.columns)) * c;  // texels from bottom-left
    for (int k = 0; k < 3; ++k) {
      tex->atlas.index[t * 3 + size_t(k)] = uint32_t(t * 3 + size_t(k));
      tex->atlas.values[t * 3 + size_t(k)] = Vec2((float(x0) + corner[k].x) / float(W), (float(y0) + corner[k].y) / float(H));
    }
  }
  tex->deferred = std::make_shared<DeferredImage>([mesh = std::move(mesh), colorAt = std::move(colorAt)] {
    return std::move(bakeAtlas(*mesh, colorAt)->image);
  });
  return tex;
}

Vec3 blobSurfaceColor(const blobtree::CompiledBlob& blob, const Vec3& p, float maxMove, const render::TextureTable& textures,
                      const render::Material& material) {
  // Each Newton step takes one sample() (value, gradient and attributes in one walk of the
  // tape), and the walk stops once the step would move the point less than a thousandth
  // of maxMove (far below a texel of the triangle's patch): a texel of a fine mesh lies
  // that close to the surface already and costs one walk, where value, gradient and a
  // final sample at each of three steps cost seven.
  const float settle = 1e-3f * maxMove;
  Vec3 q = p;
  blobtree::Sample s = blob.sample(q);
  for (int i = 0; i < 3; ++i) {
    const float f = s.value - 0.5f;
    const float g2 = glm::dot(s.gradient, s.gradient);
    if (!(g2 > 1e-20f)) break;
    const Vec3 step = (f / g2) * s.gradient;
    if (!(glm::length(step) > settle)) break;
    const Vec3 next = q - step;
    if (!std::isfinite(next.x + next.y + next.z) || glm::length(next - p) > maxMove) break;
    q = next;
    s = blob.sample(q);
  }
  return paintedColor(s.attributes, q, textures, material);
}

int atlasBlobPart(ExportPart& part, std::shared_ptr<const blobtree::CompiledBlob> blob, render::TextureTable textures,
                  render::Material material) {
  if (part.material.texture || !ownColors(part)) return 0;
  // The colours are read when a written file uses the atlas (PartTexture::deferred): from
  // the part's surface as it is now (a copy of its positions and triangles), whatever
  // finishing, placing or simplifying the part goes through first.
  auto surface = std::make_shared<Mesh>();
  surface->positions = part.mesh.positions;
  surface->triangles = part.mesh.triangles;
  auto tex = deferAtlas(surface, [surface, blob = std::move(blob), textures = std::move(textures),
                                  material = std::move(material)](size_t t, const Vec3& p, const Vec3&) {
    const glm::uvec3& tri = surface->triangles[t];
    const Vec3 &a = surface->positions[tri.x], &b = surface->positions[tri.y], &c = surface->positions[tri.z];
    const float edge = std::max({glm::length(b - a), glm::length(c - b), glm::length(a - c)});
    return blobSurfaceColor(*blob, p, edge, textures, material);
  });
  if (!tex) return 0;
  part.material.texture = tex;
  return tex->atlasCell;
}

int atlasVertexColors(ExportPart& part) {
  if (part.material.texture || !ownColors(part)) return 0;
  const Mesh& m = part.mesh;
  auto tex = bakeAtlas(m, [&m](size_t t, const Vec3&, const Vec3& b) {
    const glm::uvec3& tri = m.triangles[t];
    return b.x * m.colors[tri.x] + b.y * m.colors[tri.y] + b.z * m.colors[tri.z];
  });
  if (!tex) return 0;
  part.material.texture = tex;
  return atlasLayout(m.triangles.size()).cell;
}

void useHeaviestLayerUvs(blobtree::PolygonizeResult& result) {
  Mesh& mesh = result.mesh;
  if (result.attributes.size() != mesh.positions.size() || mesh.uvs.size() != mesh.positions.size()) return;
  for (size_t v = 0; v < mesh.uvs.size(); ++v) {
    const blobtree::Attributes& a = result.attributes[v];
    int best = -1;
    for (int i = 0; i < a.layerCount && i < blobtree::Attributes::kMaxLayers; ++i)
      if (best < 0 || a.layers[size_t(i)].weight > a.layers[size_t(best)].weight) best = i;
    if (best >= 0) mesh.uvs[v] = a.layers[size_t(best)].uv;
  }
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

ExportFinish finishExportParts(std::vector<ExportPart>& parts) {
  ExportFinish finish;
  Box3 box;
  for (ExportPart& p : parts) {
    std::vector<size_t> kept;
    finish.removed.push_back(removeDegenerateTriangles(p.mesh, &kept));
    const PartTexture* tex = p.material.texture.get();
    if (finish.removed.back().total() > 0 && tex && tex->isAtlas()) {
      auto copy = std::make_shared<PartTexture>(*tex);
      copy->atlas.index.clear();
      for (size_t t : kept)
        for (size_t k = 0; k < 3; ++k) copy->atlas.index.push_back(tex->atlas.index[t * 3 + k]);
      p.material.texture = std::move(copy);
    }
  }
  finish.offset = groundOffset(parts);
  moveParts(parts, finish.offset);
  return finish;
}

Vec3 groundOffset(const std::vector<ExportPart>& parts) {
  Box3 box;
  for (const ExportPart& p : parts)
    if (!p.mesh.triangles.empty()) box.extend(p.mesh.bounds());
  if (box.empty()) return Vec3(0.0f);
  const Vec3 centre = box.center();
  return Vec3(-centre.x, -box.lo.y, -centre.z);
}

void moveParts(std::vector<ExportPart>& parts, const Vec3& offset) {
  if (offset == Vec3(0.0f)) return;
  for (ExportPart& p : parts)
    for (Vec3& v : p.mesh.positions) v += offset;
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
  blobtree::PolygonizeOptions po = options;
  if (look.pixels) po.cellSize = render::pixelCellSize(blobtree::resolveCellSize(blob, options), *look.pixels, blob.bounds());
  blobtree::PolygonizeResult r = blobtree::polygonizeDetailed(blob, po);
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

std::vector<organisms::SimplifyReport> simplifyParts(std::vector<ExportPart>& parts, double relativeError,
                                                     std::vector<std::string>* droppedAtlases) {
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
    PartMaterial& mat = parts[i].material;
    if (mat.texture && mat.texture->isAtlas()) {
      mat.texture = nullptr;
      if (droppedAtlases) droppedAtlases->push_back(parts[i].name);
    }
  }
  return reports;
}

}  // namespace sprig
