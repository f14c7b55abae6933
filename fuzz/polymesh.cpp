/// Fuzz target: the base-mesh readers of core/polymesh.h (OBJ, PLY ascii and binary, OFF)
/// and the manifold check. The first byte picks the format, the rest is the file.
#include "core/polymesh.h"
#include "fuzz/fuzz.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using sprig::MeshFileFormat;
  if (size < 1 || size > sprig::fuzz::kMaxInput) return 0;
  const MeshFileFormat formats[] = {MeshFileFormat::Obj, MeshFileFormat::Ply, MeshFileFormat::Off};
  try {
    sprig::PolyMesh m = sprig::parsePolyMesh(sprig::fuzz::text(data + 1, size - 1), formats[data[0] % 3], "fuzz");
    sprig::DiagnosticList diags;
    sprig::checkPolyMesh(m, diags);
  } catch (const sprig::InputError&) {
  }
  return 0;
}
