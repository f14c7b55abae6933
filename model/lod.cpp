#include "model/lod.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

#include "core/mesh_clean.h"
#include "core/parallel.h"
#include "model/detail_maps.h"
#include "model/leaf_cards.h"
#include "model/mesh_parts.h"
#include "organisms/simplify.h"

namespace sprig {

namespace {

double meshArea(const Mesh& m) {
  double a = 0;
  for (const glm::uvec3& t : m.triangles)
    a += 0.5 * glm::length(glm::cross(glm::dvec3(m.positions[t.y] - m.positions[t.x]), glm::dvec3(m.positions[t.z] - m.positions[t.x])));
  return a;
}

// About targetTriangles of mesh's triangles in whole pieces (components), evenly spread over
// their order (piece j of P is kept when ⌊(j+1)·K/P⌋ > ⌊j·K/P⌋ for K pieces kept), each
// grown about its vertices' centroid by one factor so that the kept pieces cover area.
// Per-vertex arrays follow the vertices kept; per-triangle materials the triangles.
Mesh thinPieces(const Mesh& mesh, size_t targetTriangles, double area) {
  size_t pieces = 0;
  const std::vector<uint32_t> piece = triangleComponents(mesh, pieces);
  const double fraction = double(targetTriangles) / double(std::max<size_t>(mesh.triangles.size(), 1));
  const size_t keep = std::clamp<size_t>(size_t(std::floor(double(pieces) * fraction)), 1, pieces);
  std::vector<char> kept(pieces, 0);
  for (size_t j = 0; j < pieces; ++j) kept[j] = evenlyKept(j, keep, pieces);
  const std::vector<glm::dvec3> centroid = componentCentroids(mesh, piece, pieces);
  std::vector<size_t> newIndex(mesh.positions.size(), SIZE_MAX);
  Mesh out;
  std::vector<glm::dvec3> centre;  // of each output vertex's piece
  const bool normals = mesh.normals.size() == mesh.positions.size(), uvs = mesh.uvs.size() == mesh.positions.size(),
             colors = mesh.colors.size() == mesh.positions.size(), materials = mesh.materials.size() == mesh.triangles.size();
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (!kept[piece[t]]) continue;
    glm::uvec3 tri;
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[t][k];
      if (newIndex[v] == SIZE_MAX) {
        newIndex[v] = out.positions.size();
        out.positions.push_back(mesh.positions[v]);
        centre.push_back(centroid[piece[t]]);
        if (normals) out.normals.push_back(mesh.normals[v]);
        if (uvs) out.uvs.push_back(mesh.uvs[v]);
        if (colors) out.colors.push_back(mesh.colors[v]);
      }
      tri[k] = uint32_t(newIndex[v]);
    }
    out.triangles.push_back(tri);
    if (materials) out.materials.push_back(mesh.materials[t]);
  }
  const double keptArea = meshArea(out);
  const double grow = keptArea > 0 && area > 0 ? std::sqrt(area / keptArea) : 1.0;
  for (size_t v = 0; v < out.positions.size(); ++v)
    out.positions[v] = Vec3(centre[v] + (glm::dvec3(out.positions[v]) - centre[v]) * grow);
  return out;
}

// part reduced to about targetTriangles (unchanged when it has no more); error receives the
// simplification's absolute error (0 when unchanged or for scattered parts).
ExportPart reducePart(const ExportPart& part, size_t targetTriangles, float& error) {
  error = 0.0f;
  if (part.mesh.triangles.size() <= targetTriangles) return part;
  ExportPart out;
  out.name = part.name;
  out.material = part.material;
  out.scattered = part.scattered;
  if (part.scattered) {
    // Leaves: fewer triangles per leaf first (their outlines simplified, down to about two
    // triangles a leaf), then fewer leaves; the leaves that remain grown to the area all
    // of them covered, so that the crown keeps its leaf area.
    size_t pieces = 0;
    triangleComponents(part.mesh, pieces);
    const size_t floor = std::max(targetTriangles, 2 * pieces);
    const Mesh fewer =
        floor < part.mesh.triangles.size() ? organisms::simplifyToCount(part.mesh, floor, nullptr, false) : part.mesh;
    out.mesh = thinPieces(fewer, targetTriangles, meshArea(part.mesh));
  } else {
    organisms::SimplifyReport report;
    out.mesh = organisms::simplifyToCount(part.mesh, std::max<size_t>(targetTriangles, 1), &report);
    error = report.absoluteError;
  }
  removeDegenerateTriangles(out.mesh);
  // An atlas has one patch per triangle of the full part: the level's own is baked once the
  // chain is made (bakeLevelMaps), not for every trial of a level.
  if (out.material.texture && out.material.texture->isAtlas()) out.material.texture.reset();
  return out;
}

// Every part reduced to its target triangles; errors receives each part's simplification
// error (reducePart's). The parts are independent: they are reduced side by side (the wood
// beside the leaves; meshoptimizer's passes are single-threaded), each into its own slot,
// so the level is the same at any thread count.
LodLevel reduceLevel(const std::vector<ExportPart>& parts, const std::vector<size_t>& targets, std::vector<float>& errors) {
  LodLevel level;
  errors.assign(parts.size(), 0.0f);
  level.parts.resize(parts.size());
  parallelFor(0, parts.size(), [&](size_t i) {
    const ExportPart& p = parts[i];
    level.parts[i] = p.mesh.triangles.empty() ? p : reducePart(p, std::max<size_t>(targets[i], 1), errors[i]);
  });
  level.triangles = partTriangles(level.parts);
  return level;
}

// Every part's share of budget triangles: scattered parts (leaves) keep all their
// triangles up to half the budget between them (in proportion to their triangles), the
// surfaces share the rest in proportion to theirs.
std::vector<size_t> budgetShares(const std::vector<ExportPart>& parts, size_t budget) {
  size_t scattered = 0, surfaces = 0;
  for (const ExportPart& p : parts) (p.scattered ? scattered : surfaces) += p.mesh.triangles.size();
  const double scatteredShare = std::min(double(scattered), 0.5 * double(budget));
  const double surfaceShare = double(budget) - scatteredShare;
  std::vector<size_t> targets;
  for (const ExportPart& p : parts) {
    const double t = double(p.mesh.triangles.size());
    const double share = p.scattered ? (scattered ? scatteredShare * t / double(scattered) : 0.0)
                                     : (surfaces ? surfaceShare * t / double(surfaces) : 0.0);
    targets.push_back(size_t(std::llround(std::min(t, share))));
  }
  return targets;
}

// Every part's triangles times fraction.
std::vector<size_t> scaledShares(const std::vector<ExportPart>& parts, double fraction) {
  std::vector<size_t> targets;
  for (const ExportPart& p : parts) targets.push_back(size_t(std::llround(double(p.mesh.triangles.size()) * fraction)));
  return targets;
}

// Whether part is coloured by an image over its mesh's own uvs (single-bark wood, a whorl
// without growth lines, cpfg's textures) that its levels keep: not an atlas, not a cut-out.
bool ownImage(const ExportPart& part) {
  const PartTexture* t = part.material.texture.get();
  return t && !t->isAtlas() && part.material.alphaCutoff < 0.0f && part.mesh.uvs.size() == part.mesh.positions.size();
}

// Bakes every simplified surface part's normal and colour atlases from its full mesh
// (parts[i]) onto each level (a part with its own image keeps it and gets the normal map
// alone, addressed by coordinates of its own: PartMaterial::normalTexture); reach[k][i] is level k's distance bound for part i (0: the
// part is not simplified there, or has no atlas to carry maps). Every other reduced part
// gets an atlas of its own vertex colours (atlasVertexColors: where colours vary and no
// texture is set; a part that had more triangles than an atlas holds gets one too).
void bakeLevelMaps(const std::vector<ExportPart>& parts, std::vector<LodLevel>& levels,
                   const std::vector<std::vector<float>>& reach, LodMapReport& report) {
  const auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < parts.size(); ++i) {
    std::unique_ptr<DetailSurface> full;  // built for the first level that needs it
    for (size_t k = 0; k < levels.size(); ++k) {
      ExportPart& low = levels[k].parts[i];
      const bool reduced = low.mesh.triangles.size() < parts[i].mesh.triangles.size();
      if (!(reach[k][i] > 0)) {
        if (reduced) atlasVertexColors(low);
        continue;
      }
      // A part that keeps its own image reads only normals from the full mesh.
      const bool image = ownImage(low);
      if (!full) full = std::make_unique<DetailSurface>(parts[i].mesh, parts[i].material.baseColor, !image);
      DetailMaps maps = bakeDetailMaps(low.mesh, low.material.baseColor, *full, reach[k][i], !image);
      if (!maps.normal) {
        atlasVertexColors(low);
        continue;
      }
      if (!image) low.material.texture = maps.color;
      low.material.normalTexture = maps.normal;
      report.texels += maps.texels;
      report.hits += maps.hits;
      ++report.maps;
    }
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The distance bound of the detail maps of every part of every level: kDetailReach times
// the level's simplification error summed over the chain (the full mesh to LOD0 to ... to
// level k), at least kDetailReachFloor of the part's extent; 0 where the part is not a
// simplified surface whose atlas, own image (ownImage) or lack of texture can carry the maps.
std::vector<std::vector<float>> detailReach(const std::vector<ExportPart>& parts, const std::vector<LodLevel>& levels,
                                            const std::vector<std::vector<float>>& errors) {
  std::vector<std::vector<float>> reach(levels.size(), std::vector<float>(parts.size(), 0.0f));
  for (size_t i = 0; i < parts.size(); ++i) {
    const ExportPart& full = parts[i];
    if (full.scattered || full.mesh.triangles.empty() || full.mesh.normals.size() != full.mesh.positions.size()) continue;
    const Vec3 size = full.mesh.bounds().size();
    const float floor = kDetailReachFloor * std::max({size.x, size.y, size.z});
    float sum = 0.0f;
    for (size_t k = 0; k < levels.size(); ++k) {
      sum += errors[k][i];
      const ExportPart& low = levels[k].parts[i];
      const bool simplified = low.mesh.triangles.size() < full.mesh.triangles.size();
      const bool carried = !low.material.texture || low.material.texture->isAtlas() || ownImage(low);
      if (simplified && carried && !low.mesh.triangles.empty()) reach[k][i] = std::max(kDetailReach * sum, floor);
    }
  }
  return reach;
}

// The scattered parts (leaves) of level, the chain's far level, made cards from the full
// parts (leafCards): as many cards as half the triangles the level kept of them.
void cardFarLeaves(const std::vector<ExportPart>& parts, LodLevel& level) {
  for (size_t i = 0; i < parts.size(); ++i) {
    ExportPart& far = level.parts[i];
    if (!parts[i].scattered || far.mesh.triangles.empty()) continue;
    far = leafCards(parts[i], std::max<size_t>(far.mesh.triangles.size() / 2, 1));
  }
  level.triangles = partTriangles(level.parts);
}

// Crown clusters for a far level that kept leafTriangles of a part's leaves: the crown
// level's cards have about kLodRatio of them (2 triangles a card), at least one cluster.
size_t crownClusterCount(size_t leafTriangles) {
  const double cards = double(leafTriangles) * kLodRatio / 2.0;
  return std::max<size_t>(size_t(cards / double(kCrownCardsPerCluster)), 1);
}

// The crown level after far, the chain's level of per-leaf cards, or none (an empty level)
// when far has no leaves: every scattered part crown cards of the full part's leaves
// (crownCards, crownClusterCount clusters), every surface kLodRatio of far's (reducePart);
// errors receives the surfaces' simplification errors. Parts side by side, each in its slot.
LodLevel crownLevel(const std::vector<ExportPart>& parts, const LodLevel& far, std::vector<float>& errors) {
  errors.assign(parts.size(), 0.0f);
  bool leaves = false;
  for (size_t i = 0; i < parts.size(); ++i) leaves = leaves || (parts[i].scattered && !far.parts[i].mesh.triangles.empty());
  if (!leaves) return {};
  LodLevel level;
  level.parts.resize(parts.size());
  const std::vector<size_t> targets = scaledShares(far.parts, kLodRatio);
  parallelFor(0, parts.size(), [&](size_t i) {
    const ExportPart& p = far.parts[i];
    if (p.mesh.triangles.empty())
      level.parts[i] = p;
    else if (parts[i].scattered)
      level.parts[i] = crownCards(parts[i], crownClusterCount(p.mesh.triangles.size()));
    else
      level.parts[i] = reducePart(p, std::max<size_t>(targets[i], 1), errors[i]);
  });
  level.triangles = partTriangles(level.parts);
  return level;
}

}  // namespace

size_t partTriangles(const std::vector<ExportPart>& parts) {
  size_t n = 0;
  for (const ExportPart& p : parts) n += p.mesh.triangles.size();
  return n;
}

std::vector<LodLevel> buildLodChain(const std::vector<ExportPart>& parts, size_t budget, Vec3* moved,
                                    LodMapReport* maps) {
  std::vector<LodLevel> levels;
  std::vector<std::vector<float>> errors(1, std::vector<float>(parts.size(), 0.0f));  // per level, per part
  const size_t total = partTriangles(parts);
  if (total <= budget) {
    levels.push_back(LodLevel{parts, total, 0});
  } else {
    // Parts that cannot reach their share (borders locked) leave LOD0 above the budget:
    // then the budget shrinks by the overshoot, at most twice more.
    double scaled = double(budget);
    levels.push_back(reduceLevel(parts, budgetShares(parts, budget), errors[0]));
    for (int retry = 0; retry < 2 && levels[0].triangles > budget; ++retry) {
      scaled *= double(budget) / double(levels[0].triangles) * 0.98;
      levels[0] = reduceLevel(parts, budgetShares(parts, size_t(scaled)), errors[0]);
    }
  }
  while (int(levels.size()) < kLodMaxLevels) {
    const LodLevel& prev = levels.back();
    // (2 % slack: a level may come out a few triangles under its target, where the
    // simplifier removed a fold, and that must not cost the chain a level.)
    if (double(prev.triangles) * kLodRatio < 0.98 * double(kLodMinTriangles)) break;
    std::vector<float> error;
    LodLevel next = reduceLevel(prev.parts, scaledShares(prev.parts, kLodRatio), error);
    if (double(next.triangles) > double(prev.triangles) * kLodMaxKeep) break;
    levels.push_back(std::move(next));
    errors.push_back(std::move(error));
  }
  // The far level's leaves as cards, then, for a model with leaves, the crown level after it
  // (before the maps: a card part has its own texture).
  if (levels.size() > 1) {
    cardFarLeaves(parts, levels.back());
    std::vector<float> error;
    LodLevel crown = crownLevel(parts, levels.back(), error);
    if (!crown.parts.empty() && crown.triangles < levels.back().triangles) {
      levels.push_back(std::move(crown));
      errors.push_back(std::move(error));
    }
  }
  // The maps of the detail the levels lost, from the full parts (before the levels move).
  LodMapReport report;
  bakeLevelMaps(parts, levels, detailReach(parts, levels, errors), report);
  if (maps) *maps = report;
  // Simplification removes vertices at the box's sides too: LOD0 stands on the ground again
  // and every level moves with it, so the levels stay on top of each other.
  const Vec3 offset = groundOffset(levels[0].parts);
  for (LodLevel& level : levels) moveParts(level.parts, offset);
  if (moved) *moved = offset;
  for (size_t i = 0; i < levels.size(); ++i)
    levels[i].screenCoverage = i + 1 == levels.size() ? 0.0 : std::pow(kLodRatio, double(i + 1));
  return levels;
}

std::vector<LodLevel> lodLevels(std::vector<ExportPart> parts, size_t budget, Vec3* moved, LodMapReport* maps) {
  if (moved) *moved = Vec3(0.0f);
  if (maps) *maps = LodMapReport{};
  if (budget > 0) return buildLodChain(parts, budget, moved, maps);
  std::vector<LodLevel> one(1);
  one[0].triangles = partTriangles(parts);
  one[0].parts = std::move(parts);
  return one;
}

std::vector<PartWriteReport> writeLevels(const std::vector<LodLevel>& levels, const std::filesystem::path& path) {
  std::vector<std::filesystem::path> written;
  const bool glb = levels.size() > 1 && meshFormatFor(path) == MeshFormat::Glb;
  PngReuse reuse;  // OUT_lodK.glb's images are OUT.glb's: each PNG encoded once
  if (meshFormatFor(path) == MeshFormat::Glb) {
    std::vector<const ExportPart*> all;
    for (const LodLevel& level : levels)
      for (const ExportPart& p : level.parts) all.push_back(&p);
    reuse.encodeAhead(all, path);
  }
  try {
    // A .glb holds every level (readers that ignore MSFT_lod may still import the lower
    // levels' nodes: Blender 3.4 does), so LOD0 gets its own file too.
    for (size_t k = glb ? 0 : 1; k < levels.size(); ++k) {
      const std::filesystem::path file = lodPath(path, k);
      writeParts(levels[k].parts, file);
      for (const std::filesystem::path& f : partFiles(levels[k].parts, file)) written.push_back(f);
    }
    if (glb) return writePartLevels(levels, path);
    return writeParts(levels.at(0).parts, path);
  } catch (...) {
    std::error_code ec;
    for (const std::filesystem::path& f : written) std::filesystem::remove(f, ec);
    throw;
  }
}

}  // namespace sprig
