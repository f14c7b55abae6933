#include "model/kinds.h"

#include "model/blob_kind.h"
#include "model/shell_kind.h"
#include "model/tree_kind.h"

namespace sprig {

const std::vector<KindEntry>& speciesKinds() {
  static const std::vector<KindEntry> kinds = {
      {"tree", readTreeSpec},
      {"shell", readShellSpec},
      {"blob", readBlobSpec},
  };
  return kinds;
}

const KindEntry* findKind(const std::string& name) {
  for (const KindEntry& k : speciesKinds())
    if (name == k.name) return &k;
  return nullptr;
}

const char* geometryModeName(GeometryMode mode) {
  switch (mode) {
    case GeometryMode::Exact: return "exact";
    case GeometryMode::Mesh: return "mesh";
    case GeometryMode::Skeleton: return "skeleton";
  }
  return "?";
}

Stage KindModel::stageAtAge(double) const { throw UsageError("--age applies to shell species only"); }

}  // namespace sprig
