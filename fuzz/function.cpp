/// Fuzz target: the readers of cpfg's side files, which a view file names, on any bytes.
/// The first byte picks the reader (its value modulo 5), the rest is the file:
///   0  function file (lsystem::CpfgFunction::parse, both formats), then func(n, x) at a
///      few arguments;
///   1  curve file (CpfgCurve::parse), then curveX/Y/Z at a few lengths;
///   2  contour file (CpfgContour::parse, every version), then its resampling at a few
///      side counts;
///   3  surface file (CpfgSurface::parse), tessellated at the file's precision, and at a
///      view file's size and precisions;
///   4  materials file (parseCpfgMaterials, binary records), whose palette must have 256
///      entries in [0, 1] (a trap otherwise).
#include "fuzz/fuzz.h"
#include <cstdlib>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "lsystem/cpfg_contour.h"
#include "lsystem/cpfg_curve.h"
#include "lsystem/cpfg_function.h"
#include "lsystem/cpfg_materials.h"
#include "lsystem/cpfg_surface.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace sprig::lsystem;
  if (size < 1 || size > sprig::fuzz::kMaxInput) return 0;
  const std::string text(sprig::fuzz::text(data + 1, size - 1));
  try {
    switch (data[0] % 5) {
      case 0: {
        const CpfgFunction f = CpfgFunction::parse(text, "fuzz.func", -1);
        for (double x : {0.0, 0.25, 0.5, 1.0}) (void)f.value(x);
        break;
      }
      case 1: {
        const CpfgCurve c = CpfgCurve::parse(text, "fuzz.crv", 20);
        for (double t : {-1.0, 0.0, 0.3, 1.0, 2.0}) (void)c.atLength(t);
        (void)c.point(1.0);
        break;
      }
      case 2: {
        const CpfgContour c = CpfgContour::parse(text, "fuzz.con");
        for (int sides : {CpfgContour::kMinSides, CpfgContour::kDefaultSides, 37}) (void)c.sample(sides);
        break;
      }
      case 3: {
        (void)CpfgSurface::parse(text, "fuzz.s", 0.0, 0, 0);
        (void)CpfgSurface::parse(text, "fuzz.s", 2.5, 3, 7);
        break;
      }
      default: {
        std::vector<sprig::Diagnostic> notes;
        const std::vector<sprig::Vec3> palette = parseCpfgMaterials(text, "fuzz.mat", notes);
        if (palette.size() != 256) std::abort();
        for (const sprig::Vec3& c : palette)
          for (int k = 0; k < 3; ++k)
            if (!(c[k] >= 0.0f && c[k] <= 1.0f)) std::abort();
        if (notes.size() > text.size() / kCpfgMaterialRecord) std::abort();
        break;
      }
    }
  } catch (const sprig::InputError&) {
  }
  return 0;
}
