/// Fuzz target: cpfg's background scene reader (lsystem::parseCpfgBackground) and its
/// triangles, on any bytes. A scene read without an error must triangulate into finite
/// positions, unit normals, indices in range and a valid material per triangle (a trap
/// otherwise).
#include "fuzz/fuzz.h"

#include <cmath>
#include <string>
#include <vector>

#include "lsystem/cpfg_background.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  try {
    std::vector<sprig::Diagnostic> warnings;
    const sprig::lsystem::CpfgBackground b =
        sprig::lsystem::parseCpfgBackground({std::string(sprig::fuzz::text(data, size))}, {"fuzz.dat"}, warnings);
    const sprig::lsystem::CpfgBackgroundMesh m = b.triangulate();
    if (m.normals.size() != m.positions.size() || m.triangles.size() != 3 * m.triangleMaterials.size()) __builtin_trap();
    for (uint32_t i : m.triangles)
      if (i >= m.positions.size()) __builtin_trap();
    for (int mat : m.triangleMaterials)
      if (mat < 0 || static_cast<size_t>(mat) >= b.materials.size()) __builtin_trap();
  } catch (const sprig::InputError&) {
  }
  return 0;
}
