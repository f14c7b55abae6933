#pragma once
/// Scalar volumes in the INRIMAGE-4 format (`.inr`), the format of CT and MRI volumes that
/// CGAL's demos and INRIA's tools use (Debian's libcgal-demo ships the CT skull of Velho
/// et al.'s Fig. 11 and 13 as one).
///
/// The header is text: `#INRIMAGE-4#{`, then `KEY=value` lines, blank padding, `##}` and a
/// newline, its whole length a multiple of 256 bytes. Sprig reads XDIM, YDIM, ZDIM, VDIM
/// (must be 1), TYPE (`float`, `unsigned fixed`, `signed fixed`), PIXSIZE (`8 bits`,
/// `16 bits`, `32 bits`, `64 bits`), CPU (byte order: `decm`, `alpha`, `pc` little-endian;
/// `sun`, `sgi` big-endian), VX, VY, VZ (voxel size, default 1) and TX, TY, TZ (origin,
/// default 0); `SCALE` must be `2**0` (fixed-point scaling is not implemented), lines
/// starting with `#` are comments, and any other key is an error naming it. The voxels
/// follow the header, x fastest, and must fill the rest of the file exactly.
///
/// Limits: each dimension at most 4096, at most 2^30 voxels in all (4 GiB of floats).

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"

namespace sprig {

/// A scalar volume: value(i, j, k) at position origin + (i vx, j vy, k vz).
struct ScalarVolume {
  std::array<int, 3> dims{0, 0, 0};
  std::array<double, 3> voxel{1, 1, 1};
  std::array<double, 3> origin{0, 0, 0};
  std::vector<float> values;  ///< dims[0] * dims[1] * dims[2], x fastest

  float at(int i, int j, int k) const { return values[(size_t(k) * dims[1] + j) * dims[0] + i]; }
};

/// Size limits of the INR reader.
struct VolumeLimits {
  int maxDimension = 4096;
  uint64_t maxVoxels = uint64_t(1) << 30;
};

/// Parses an INR volume held in memory; displayPath names it in messages. Every header
/// error is an InputError at its line and column. O(voxels).
ScalarVolume parseInrVolume(std::string_view bytes, const std::string& displayPath, const VolumeLimits& limits = {});

/// Reads an INR volume file (InputError when it cannot be read or is malformed).
ScalarVolume readInrVolume(const std::filesystem::path& path, std::string displayPath = {},
                           const VolumeLimits& limits = {});

}  // namespace sprig
