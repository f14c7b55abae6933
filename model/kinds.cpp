#include "model/kinds.h"

#include <iterator>

#include "model/blob_kind.h"
#include "model/organism_kind.h"
#include "model/shell_kind.h"
#include "model/solid_kind.h"
#include "model/tree_kind.h"

namespace sprig {

const std::vector<KindEntry>& speciesKinds() {
  static const std::vector<KindEntry> kinds = {
      {"tree", readTreeSpec},
      {"shell", readShellSpec},
      {"blob", readBlobSpec},
      {"organism", readOrganismSpec},
      {"solid", readSolidSpec},
  };
  return kinds;
}

const KindEntry* findKind(const std::string& name) {
  for (const KindEntry& k : speciesKinds())
    if (name == k.name) return &k;
  return nullptr;
}

const char* geometryModeName(GeometryMode mode) {
  static constexpr const char* kNames[] = {"exact", "mesh", "skeleton"};  // in enum order
  const auto i = static_cast<size_t>(mode);
  return i < std::size(kNames) ? kNames[i] : "?";
}

GeometryMode geometryModeNamed(const std::string& name) {
  for (GeometryMode m : {GeometryMode::Exact, GeometryMode::Mesh, GeometryMode::Skeleton})
    if (name == geometryModeName(m)) return m;
  throw UsageError("--mode " + name + ": expected exact, mesh or skeleton");
}

Box3 KindModel::partBox(const CloseUpSpec& target) {
  throw InputError(target.loc, "render.close_up: this kind has no internodes or junctions to frame (frame a 'point' with a 'size')");
}

Stage KindModel::stageAtAge(double) const { throw UsageError("--age applies to shell species only"); }

std::string KindModel::writeVolumeMesh(const Stage&, const std::filesystem::path& path, bool) {
  throw UsageError("'" + path.extension().string() + "' is a tetrahedral mesh format: only solid species have one");
}

std::vector<ExportPart> KindModel::exportParts(const Stage& stage, float cellSize, bool progress, const SpeciesRender& look,
                                              const MeshCleanOptions&, ModelFigures& figures) {
  ExportPart part;
  part.name = "surface";
  part.mesh = buildMesh(stage, cellSize, progress, figures);
  part.material.name = "surface";
  part.material.baseColor = look.surface.baseColor;
  part.material.roughness = look.surface.roughness;
  return {std::move(part)};
}

std::vector<std::pair<std::string, Mesh>> KindModel::interfaceMeshes(const Stage&) {
  throw UsageError("--interfaces applies to solid species only (their material interfaces)");
}

}  // namespace sprig
