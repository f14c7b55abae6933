#include "lsystem/cpfg_materials.h"

#include <cstdio>

namespace sprig::lsystem {

std::vector<Vec3> parseCpfgMaterials(std::string_view bytes, const std::string& fileName, std::vector<Diagnostic>& notes) {
  if (bytes.empty() || bytes.size() % kCpfgMaterialRecord != 0)
    throw InputError(SourceLoc{fileName, 0, 0},
                     "a cpfg materials file holds records of 15 bytes (colour index, transparency, ambient, diffuse, "
                     "emissive, specular, shininess), this file has " +
                         std::to_string(bytes.size()) + " bytes");
  auto byte = [&](size_t i) { return static_cast<unsigned char>(bytes[i]); };
  std::vector<Vec3> palette(256, Vec3(1.0f));
  for (size_t r = 0; r < bytes.size(); r += kCpfgMaterialRecord) {
    const unsigned index = byte(r);
    for (int c = 0; c < 3; ++c) palette[index][c] = static_cast<float>(byte(r + 5 + static_cast<size_t>(c))) / 255.0f;
    if (byte(r + 1) != 0) {
      Diagnostic d;
      d.severity = Severity::Note;
      d.loc = SourceLoc{fileName, 0, 0};
      char t[16];
      std::snprintf(t, sizeof t, "%.2f", static_cast<double>(byte(r + 1)) / 255.0);
      d.message = "material " + std::to_string(index) + " has transparency " + t + ": Sprig draws it opaque";
      notes.push_back(std::move(d));
    }
  }
  return palette;
}

}  // namespace sprig::lsystem
