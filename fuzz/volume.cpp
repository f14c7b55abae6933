/// Fuzz target: the INR volume reader of core/inr_volume.h, then, for a volume of at most
/// 16^3 voxels, the iso-surface of organisms/iso_surface.h at the volume's mean value and
/// the manifold check of the mesh it makes.
#include <numeric>
#include <stdexcept>

#include "core/inr_volume.h"
#include "core/polymesh.h"
#include "fuzz/fuzz.h"
#include "organisms/iso_surface.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > sprig::fuzz::kMaxInput) return 0;
  sprig::VolumeLimits limits;
  limits.maxVoxels = 16 * 16 * 16;
  try {
    const sprig::ScalarVolume v = sprig::parseInrVolume(sprig::fuzz::text(data, size), "fuzz.inr", limits);
    const double mean = std::accumulate(v.values.begin(), v.values.end(), 0.0) / double(v.values.size());
    const sprig::PolyMesh m = sprig::organisms::isoSurface(v, mean);
    sprig::DiagnosticList diags;
    const sprig::PolyTopology t = sprig::checkPolyMesh(m, diags);
    if (diags.hasErrors() || !t.closed() || !t.manifold()) __builtin_trap();  // the surface must be closed
  } catch (const sprig::InputError&) {
  } catch (const std::invalid_argument&) {  // an iso value that does not cross the volume
  }
  return 0;
}
